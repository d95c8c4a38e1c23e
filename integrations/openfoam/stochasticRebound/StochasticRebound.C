/*---------------------------------------------------------------------------*\
    stochasticRebound: a patch interaction model for OpenFOAM's Lagrangian
    clouds that draws the rebound of non-spherical particles from a
    rebound-scatter table through the rebound-scatter C runtime.

    Copyright (C) 2026 the rebound-scatter authors
-------------------------------------------------------------------------------
License
    This file is part of the rebound-scatter OpenFOAM adapter, which is
    derived from and links with OpenFOAM.

    This program is free software: you can redistribute it and/or modify it
    under the terms of the GNU General Public License as published by the
    Free Software Foundation, either version 3 of the License, or (at your
    option) any later version.

    This program is distributed in the hope that it will be useful, but
    WITHOUT ANY WARRANTY; without even the implied warranty of
    MERCHANTABILITY or FITNESS FOR A PARTICULAR PURPOSE.  See the GNU General
    Public License for more details.

    You should have received a copy of the GNU General Public License along
    with this program (integrations/openfoam/LICENSE).  If not, see
    <http://www.gnu.org/licenses/>.

\*---------------------------------------------------------------------------*/

#include "StochasticRebound.H"
#include "Pstream.H"
#include "OSspecific.H"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <type_traits>
#include <utility>

// * * * * * * * * * * * * * * * * Spin helpers  * * * * * * * * * * * * * * //

namespace Foam
{
namespace stochasticReboundDetail
{

// Colliding parcels carry an angular momentum; the others no spin.

template<class P>
auto angularVelocity(const P& p, int)
    -> decltype(p.angularMomentum(), vector())
{
    const scalar I = p.momentOfInertia();
    return I > 0 ? vector(p.angularMomentum()/I) : vector(Zero);
}

template<class P>
vector angularVelocity(const P&, long)
{
    return Zero;
}

template<class P>
auto setAngularVelocity(P& p, const vector& omega, int)
    -> decltype(p.angularMomentum() = omega, void())
{
    p.angularMomentum() = p.momentOfInertia()*omega;
}

template<class P>
void setAngularVelocity(P&, const vector&, long)
{}

template<class P>
struct hasSpin
{
    template<class Q>
    static auto test(int)
        -> decltype(std::declval<const Q&>().angularMomentum(), std::true_type());

    template<class>
    static std::false_type test(...);

    static constexpr bool value = decltype(test<P>(0))::value;
};

} // End namespace stochasticReboundDetail
} // End namespace Foam


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

template<class CloudType>
void Foam::StochasticRebound<CloudType>::openTable(const dictionary& dict)
{
    tableFile_ = dict.get<fileName>("table");
    tableFile_.expand();
    if (!tableFile_.isAbsolute())
    {
        tableFile_ = this->owner().mesh().time().globalPath()/tableFile_;
    }

    char message[512] = "";
    rbs_table* table = nullptr;
    const int err =
        rbs_table_open(tableFile_.c_str(), &table, message, sizeof(message));
    if (err != RBS_OK)
    {
        FatalIOErrorInFunction(dict)
            << "Cannot open the rebound table " << tableFile_ << ": "
            << rbs_status_string(err) << ": " << message
            << exit(FatalIOError);
    }
    table_.reset(table, rbs_table_close);

    rbs_table_info info = RBS_TABLE_INFO_INIT;
    const int infoErr = rbs_table_info_get(table, &info);
    if (infoErr != RBS_OK)
    {
        FatalIOErrorInFunction(dict)
            << "Cannot read the grids of the rebound table " << tableFile_
            << ": " << rbs_status_string(infoErr) << exit(FatalIOError);
    }
    alpha1Lo_ = info.alpha1_min_deg;
    alpha1Hi_ = info.alpha1_max_deg;
    speedLo_ = info.speed_min_m_s;
    speedHi_ = info.speed_max_m_s;

    // The shape mix: `weights { prism 0.7; tetrahedron 0.3; }` or `shape`
    if (dict.found("weights"))
    {
        const dictionary& wd = dict.subDict("weights");
        const wordList names(wd.toc());
        List<std::string> keep(names.size());
        List<const char*> cnames(names.size());
        List<double> weights(names.size());
        OStringStream desc;
        forAll(names, i)
        {
            keep[i] = names[i];
            cnames[i] = keep[i].c_str();
            weights[i] = wd.get<scalar>(names[i]);
            desc<< (i ? ", " : "") << names[i] << ' ' << weights[i];
        }
        mix_.reset
        (
            rbs_mix_new_from_weights
            (
                table, names.size(), cnames.cdata(), weights.cdata(),
                message, sizeof(message)
            ),
            rbs_mix_free
        );
        if (!mix_)
        {
            FatalIOErrorInFunction(dict)
                << "Bad shape weights: " << message << exit(FatalIOError);
        }
        mixName_ = "weights (" + desc.str() + ")";
    }
    else
    {
        const word shape(dict.getOrDefault<word>("shape", "mix"));
        // A mix sized by the table (any number of shapes): one shape, or
        // "mix", equal weights over the table's shapes
        mix_.reset
        (
            rbs_mix_new_from_shape(table, shape.c_str(), message, sizeof(message)),
            rbs_mix_free
        );
        if (!mix_)
        {
            FatalIOErrorInFunction(dict)
                << "Bad shape " << shape << ": " << message
                << exit(FatalIOError);
        }
        mixName_ = shape;
    }
}


template<class CloudType>
void Foam::StochasticRebound<CloudType>::recordHit
(
    const typename CloudType::parcelType& p,
    const polyPatch& pp,
    const double V[3],
    const double Omega[3],
    const double n[3],
    const vector& Uwall,
    double a,
    const rbs_result& result,
    int path,
    int64_t key,
    scalar spinRatio,
    double u0
)
{
    State& s = *state_;
    if (!s.hits.is_open() || s.nRecorded >= maxHitRecords_)
    {
        return;
    }
    ++s.nRecorded;

    // The grain: its shape under grain kept (empty for a new grain per
    // hit; the result's, else, for a hit refused, the key's), and b/a, c/b
    // and the hand where the direct path fixed them (NaN on the table path,
    // which draws them from the shape's law)
    const char* shape = "";
    double ratioBa = NAN, ratioCb = NAN, hand = NAN;
    if (key >= 0)
    {
        int grainShape = result.shape;
        if (grainShape < 0 || path == RBS_PATH_DIRECT)
        {
            rbs_grain grain = RBS_GRAIN_INIT;
            if
            (
                rbs_grain_info(table_.get(), mix_.get(), key, &grain)
             == RBS_OK
            )
            {
                grainShape = grain.shape;
                if (path == RBS_PATH_DIRECT)
                {
                    ratioBa = grain.ratio_ba;
                    ratioCb = grain.ratio_cb;
                    hand = grain.hand;
                }
            }
        }
        if (grainShape >= 0)
        {
            shape = rbs_table_shape_name(table_.get(), grainShape);
        }
    }

    char line[1024];
    std::snprintf
    (
        line, sizeof(line),
        "%.9g,%d,%s,%d,%d,%.9g,%.9g,"
        "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
        "%.9g,%.9g,%.9g,"
        "%d,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.9g,%.17g,"
        "%lld,%s,%.17g,%.17g,%g\n",
        this->owner().mesh().time().value(),
        int(Pstream::myProcNo()), pp.name().c_str(),
        int(p.origProc()), int(p.origId()), p.d(), a,
        V[0], V[1], V[2], Omega[0], Omega[1], Omega[2], n[0], n[1], n[2],
        Uwall.x(), Uwall.y(), Uwall.z(),
        result.status, path, result.V[0], result.V[1], result.V[2],
        result.Omega[0], result.Omega[1], result.Omega[2], spinRatio, u0,
        static_cast<long long>(key), shape, ratioBa, ratioCb, hand
    );
    s.hits << line;
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

template<class CloudType>
Foam::StochasticRebound<CloudType>::StochasticRebound
(
    const dictionary& dict,
    CloudType& cloud
)
:
    PatchInteractionModel<CloudType>(dict, cloud, typeName),
    tableFile_(),
    table_(),
    mix_(),
    mixName_(),
    halfSizeFactor_
    (
        this->coeffDict().template getOrDefault<scalar>("halfSizeFactor", 1)
    ),
    removeTrapped_(false),
    seed_(0),
    interpolation_(RBS_INTERPOLATION_SCALED),
    method_(RBS_METHOD_AUTO),
    keepGrain_(true),
    grainSeed_(0),
    alpha1Lo_(0),
    alpha1Hi_(0),
    speedLo_(0),
    speedHi_(0),
    writeHits_
    (
        this->coeffDict().template getOrDefault<bool>("writeHits", false)
    ),
    maxHitRecords_
    (
        this->coeffDict().template getOrDefault<label>
        (
            "maxHitRecords", 1000000
        )
    ),
    state_(new State())
{
    const dictionary& coeffs = this->coeffDict();

    // A misspelled entry would silently fall back to its default: refuse the
    // entries neither this model nor its base classes read
    static const wordList known
    ({
        "table", "shape", "weights", "halfSizeFactor", "trapped", "seed",
        "interpolation", "method", "grain", "grainSeed", "writeHits", "maxHitRecords",
        "U", "writePrecision", "writeToFile", "useUserTime", "defaultCoeffs"
    });
    for (const word& key : coeffs.toc())
    {
        if (!known.found(key))
        {
            FatalIOErrorInFunction(coeffs)
                << "unknown entry " << key << " in " << coeffs.dictName()
                << "; the entries are " << known
                << exit(FatalIOError);
        }
    }
    if (coeffs.found("shape") && coeffs.found("weights"))
    {
        FatalIOErrorInFunction(coeffs)
            << "shape and weights are both given in " << coeffs.dictName()
            << ": give one of them (weights would take precedence unseen)"
            << exit(FatalIOError);
    }
    if (maxHitRecords_ < 0)
    {
        FatalIOErrorInFunction(coeffs)
            << "maxHitRecords must be >= 0, not " << maxHitRecords_
            << exit(FatalIOError);
    }

    if (halfSizeFactor_ <= 0)
    {
        FatalIOErrorInFunction(coeffs)
            << "halfSizeFactor must be > 0, not " << halfSizeFactor_
            << exit(FatalIOError);
    }

    const word trapped(coeffs.getOrDefault<word>("trapped", "stick"));
    if (trapped == "remove")
    {
        removeTrapped_ = true;
    }
    else if (trapped != "stick")
    {
        FatalIOErrorInFunction(coeffs)
            << "trapped must be stick or remove, not " << trapped
            << exit(FatalIOError);
    }

    const word interp(coeffs.getOrDefault<word>("interpolation", "scaled"));
    if (interp == "stochastic")
    {
        interpolation_ = RBS_INTERPOLATION_STOCHASTIC;
    }
    else if (interp != "scaled")
    {
        FatalIOErrorInFunction(coeffs)
            << "interpolation must be scaled or stochastic, not " << interp
            << exit(FatalIOError);
    }

    const word method(coeffs.getOrDefault<word>("method", "auto"));
    if (method == "table")
    {
        method_ = RBS_METHOD_TABLE;
    }
    else if (method == "direct")
    {
        method_ = RBS_METHOD_DIRECT;
    }
    else if (method != "auto")
    {
        FatalIOErrorInFunction(coeffs)
            << "method must be auto, table or direct, not " << method
            << exit(FatalIOError);
    }

    const word grainMode(coeffs.getOrDefault<word>("grain", "kept"));
    if (grainMode == "perHit")
    {
        keepGrain_ = false;
    }
    else if (grainMode != "kept")
    {
        FatalIOErrorInFunction(coeffs)
            << "grain must be kept or perHit, not " << grainMode
            << exit(FatalIOError);
    }

    const label seed = coeffs.getOrDefault<label>("seed", 1);
    if (seed < 0)
    {
        FatalIOErrorInFunction(coeffs)
            << "seed must be >= 0, not " << seed << exit(FatalIOError);
    }
    seed_ = uint64_t(seed);

    // The keys' own seed, so that a restart may draw new streams (another
    // seed) while every parcel keeps its grain
    const label grainSeed = coeffs.getOrDefault<label>("grainSeed", seed);
    if (grainSeed < 0)
    {
        FatalIOErrorInFunction(coeffs)
            << "grainSeed must be >= 0, not " << grainSeed
            << exit(FatalIOError);
    }
    grainSeed_ = uint64_t(grainSeed);

    openTable(coeffs);

    // Rank r draws stream r of the seed: no two ranks share draws
    const label stream = Pstream::myProcNo();
    rbs_rng_seed_stream(&state_->rng, seed_, uint64_t(stream));

    if (writeHits_)
    {
        const fileName dir
        (
            this->owner().mesh().time().globalPath()/"postProcessing"
           /"lagrangian"/this->owner().name()/typeName
        );
        mkDir(dir);
        const fileName file(dir/("hits_" + Foam::name(stream) + ".csv"));
        state_->hits.open(file.c_str(), std::ios::out | std::ios::trunc);
        if (!state_->hits)
        {
            FatalErrorInFunction
                << "Cannot write " << file << exit(FatalError);
        }
        state_->hits
            << "# stochasticRebound hits: seed " << seed_ << ", stream "
            << stream << ", table " << tableFile_.c_str() << ", mix "
            << mixName_.c_str() << ", halfSizeFactor " << halfSizeFactor_
            << ", interpolation " << interp.c_str() << ", method "
            << method.c_str() << ", spin tolerance " << RBS_SPIN_TOLERANCE
            << ", grain " << grainMode.c_str();
        if (keepGrain_)
        {
            state_->hits << " (key seed " << grainSeed_ << ")";
        }
        state_->hits << "\n"
            << "# V: incident velocity relative to the wall, Win: incident"
               " angular velocity (colliding parcels, else 0), n: unit normal"
               " into the gas, Uw: wall velocity, path: 0 table, 1 direct"
               " model, -1 invalid, Vout/Wout: rebound velocity (relative to"
               " the wall) and angular velocity, spin_ratio: |Win| a/|V|,"
               " u0: first uniform of the draw, key: the parcel's grain key"
               " (-1: a new grain per hit), shape: its shape (empty: drawn"
               " per hit), ratio_ba/ratio_cb/hand: its b/a, c/b and hand on"
               " the direct path (nan: the table path or not random)\n"
            << "time,rank,patch,origProc,origId,d,a,Vx,Vy,Vz,Winx,Winy,Winz,"
               "nx,ny,nz,Uwx,Uwy,Uwz,status,path,Voutx,Vouty,Voutz,Wx,Wy,Wz,"
               "spin_ratio,u0,key,shape,ratio_ba,ratio_cb,hand\n";
    }

    const rbs_table* t = table_.get();
    Info<< "    stochasticRebound: table " << tableFile_
        << " (" << rbs_table_n_shapes(t) << " shapes, alpha1 " << alpha1Lo_
        << "-" << alpha1Hi_ << " deg, |V| " << speedLo_ << "-" << speedHi_
        << " m/s)" << nl
        << "        shape " << mixName_.c_str() << ", a = " << halfSizeFactor_
        << "*d/2, trapped parcels " << (removeTrapped_ ? "removed" : "stick")
        << ", interpolation " << interp << ", method " << method
        << " (spin tolerance " << RBS_SPIN_TOLERANCE << ")"
        << ", seed " << seed_
        << " (rank r draws stream r)" << nl
        << "        grain " << grainMode
        << (
               keepGrain_
             ? " (a parcel's key from grainSeed, origProc, origId; grainSeed "
             : " (a new grain from the mix at every hit"
           );
    if (keepGrain_)
    {
        Info<< grainSeed_;
    }
    Info<< ")" << endl;
}


template<class CloudType>
Foam::StochasticRebound<CloudType>::StochasticRebound
(
    const StochasticRebound<CloudType>& pim
)
:
    PatchInteractionModel<CloudType>(pim),
    tableFile_(pim.tableFile_),
    table_(pim.table_),
    mix_(pim.mix_),
    mixName_(pim.mixName_),
    halfSizeFactor_(pim.halfSizeFactor_),
    removeTrapped_(pim.removeTrapped_),
    seed_(pim.seed_),
    interpolation_(pim.interpolation_),
    method_(pim.method_),
    keepGrain_(pim.keepGrain_),
    grainSeed_(pim.grainSeed_),
    alpha1Lo_(pim.alpha1Lo_),
    alpha1Hi_(pim.alpha1Hi_),
    speedLo_(pim.speedLo_),
    speedHi_(pim.speedHi_),
    writeHits_(pim.writeHits_),
    maxHitRecords_(pim.maxHitRecords_),
    state_(pim.state_)
{}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

template<class CloudType>
bool Foam::StochasticRebound<CloudType>::correct
(
    typename CloudType::parcelType& p,
    const polyPatch& pp,
    bool& keepParticle
)
{
    if (!isA<wallPolyPatch>(pp))
    {
        // Stock behaviour for every other patch type
        return false;
    }

    State& s = *state_;
    Counters& c = s.counters;

    // OpenFOAM's normal at the hit point points out of the domain (into the
    // wall); the wall velocity includes a moving wall's tangential velocity
    vector nw, Uwall;
    this->owner().patchData(p, pp, nw, Uwall);

    vector& U = p.U();
    const vector Vin(U - Uwall);
    const vector Win(stochasticReboundDetail::angularVelocity(p, 0));
    const scalar nMag = mag(nw);
    const scalar a = halfSizeFactor_*0.5*p.d();

    // The hit: V⁻, Ω⁻, n into the gas, a, the parcel's grain key, and the 13
    // uniforms it takes whatever the path (drawn here, the first one is
    // recorded)
    rbs_hit hit = RBS_HIT_INIT;
    hit.V[0] = Vin.x();
    hit.V[1] = Vin.y();
    hit.V[2] = Vin.z();
    hit.Omega[0] = Win.x();
    hit.Omega[1] = Win.y();
    hit.Omega[2] = Win.z();
    if (nMag > 0)
    {
        // Ours points into the gas, unit length in double precision
        hit.n[0] = -nw.x()/nMag;
        hit.n[1] = -nw.y()/nMag;
        hit.n[2] = -nw.z()/nMag;
    }
    hit.a = a;
    // grain kept: the parcel's ids, born with it, carried across ranks and
    // restarts, give its key; perHit: RBS_NO_KEY, a new grain per hit
    hit.grain_key =
        keepGrain_
      ? rbs_grain_key(grainSeed_, uint64_t(p.origProc()), uint64_t(p.origId()))
      : RBS_NO_KEY;
    double u[RBS_U_PER_DRAW];
    rbs_rng_fill(&s.rng, u, RBS_U_PER_DRAW);
    hit.u = u;

    rbs_options options = RBS_OPTIONS_INIT;
    options.method = method_;
    options.interpolation = interpolation_;

    // The path is a pure function of the state: learnt before the draw,
    // so the clock runs around the direct model's calls only
    const rbs_table* table = table_.get();
    const int path = rbs_rebound_path(table, &hit, &options);
    std::chrono::steady_clock::time_point t0;
    if (path == RBS_PATH_DIRECT)
    {
        t0 = std::chrono::steady_clock::now();
    }
    rbs_result result = RBS_RESULT_INIT;
    const int status = rbs_rebound(table, mix_.get(), &hit, &options, &result);
    if (path == RBS_PATH_DIRECT)
    {
        c.directSeconds += std::chrono::duration<double>
        (
            std::chrono::steady_clock::now() - t0
        ).count();
        ++c.directPath;
    }
    else if (path == RBS_PATH_TABLE)
    {
        ++c.tablePath;
    }

    ++c.hits;

    const scalar speed = mag(Vin);
    const scalar spinRatio = speed > 0 ? mag(Win)*a/speed : 0;
    if (stochasticReboundDetail::hasSpin<typename CloudType::parcelType>::value)
    {
        ++c.spinSamples;
        c.spinRatioSum += spinRatio;
        c.spinRatioMax = max(c.spinRatioMax, spinRatio);
    }

    if (status != RBS_INVALID)
    {
        // Outside the table's grid: the direct model answers under auto and
        // direct, the law at the nearest grid edge under table
        const scalar Vn =
            hit.V[0]*hit.n[0] + hit.V[1]*hit.n[1] + hit.V[2]*hit.n[2];
        const scalar alpha1 = radToDeg
        (
            std::asin(min(max(-Vn/speed, -1), 1))
        );
        if
        (
            speed < speedLo_ || speed > speedHi_
         || alpha1 < alpha1Lo_ || alpha1 > alpha1Hi_
        )
        {
            ++c.outsideGrid;
        }
    }

    switch (status)
    {
        case RBS_OK:
        {
            ++c.rebounded;
            keepParticle = true;
            p.active(true);
            U = vector(result.V[0], result.V[1], result.V[2]) + Uwall;
            stochasticReboundDetail::setAngularVelocity
            (
                p,
                vector(result.Omega[0], result.Omega[1], result.Omega[2]),
                0
            );
            break;
        }
        case RBS_TRAPPED:
        case RBS_FAILED:
        {
            // A failed direct rebound has no answer: the trapped policy
            // applies, counted apart
            if (status == RBS_TRAPPED)
            {
                ++c.trapped;
                c.trappedMass += p.nParticle()*p.mass();
            }
            else
            {
                ++c.failed;
                c.failedMass += p.nParticle()*p.mass();
            }
            // stick: kept, inactive, at rest on the wall; remove: deleted
            keepParticle = !removeTrapped_;
            p.active(false);
            U = Zero;
            stochasticReboundDetail::setAngularVelocity(p, vector(Zero), 0);
            break;
        }
        default:
        {
            // Not moving into the wall (or a degenerate normal): the stock
            // rebound leaves such a parcel's velocity as it is
            ++c.invalid;
            keepParticle = true;
            break;
        }
    }

    if (s.hits.is_open())
    {
        recordHit
        (
            p, pp, hit.V, hit.Omega, hit.n, Uwall, a, result, path,
            hit.grain_key, spinRatio, u[0]
        );
    }

    return true;
}


template<class CloudType>
void Foam::StochasticRebound<CloudType>::info(Ostream& os)
{
    PatchInteractionModel<CloudType>::info(os);

    State& s = *state_;
    const Counters& c = s.counters;

    // Totals: the values stored at the last write plus this run's since then
    auto total = [this](const word& name, label now)
    {
        return this->template getModelProperty<label>(name)
            + returnReduce(now, sumOp<label>());
    };
    auto totalScalar = [this](const word& name, scalar now)
    {
        return this->template getModelProperty<scalar>(name)
            + returnReduce(now, sumOp<scalar>());
    };
    const label nHits = total("nHits", c.hits);
    const label nTable = total("nTablePath", c.tablePath);
    const label nDirect = total("nDirectPath", c.directPath);
    const label nRebounded = total("nRebounded", c.rebounded);
    const label nTrapped = total("nTrapped", c.trapped);
    const label nFailed = total("nFailed", c.failed);
    const label nInvalid = total("nInvalid", c.invalid);
    const label nOutside = total("nOutsideGrid", c.outsideGrid);
    const scalar mTrapped = totalScalar("massTrapped", c.trappedMass);
    const scalar mFailed = totalScalar("massFailed", c.failedMass);
    const scalar directSeconds =
        totalScalar("directModelSeconds", c.directSeconds);
    label nSpin = this->template getModelProperty<label>("nSpinSamples");
    scalar spinSum = this->template getModelProperty<scalar>("spinRatioSum");
    scalar spinMax = this->template getModelProperty<scalar>("spinRatioMax");

    const char* policy = removeTrapped_ ? "removed" : "stuck";
    os  << "    Stochastic rebound (" << mixName_.c_str() << ')' << nl
        << "      - wall hits                   = " << nHits << nl
        << "      - answered by the table       = " << nTable << nl
        << "      - answered by the direct model = " << nDirect
        << " (mean cost " << (nDirect > 0 ? 1e6*directSeconds/nDirect : 0)
        << " us per hit)" << nl
        << "      - rebounded                   = " << nRebounded << nl
        << "      - trapped, " << policy << " (number, mass) = "
        << nTrapped << ", " << mTrapped << nl
        << "      - failed (direct model), " << policy << " (number, mass) = "
        << nFailed << ", " << mFailed << nl
        << "      - invalid (left as stock)     = " << nInvalid << nl
        << "      - outside the table's grid    = " << nOutside << nl;

    if (stochasticReboundDetail::hasSpin<typename CloudType::parcelType>::value)
    {
        nSpin += returnReduce(c.spinSamples, sumOp<label>());
        spinSum += returnReduce(c.spinRatioSum, sumOp<scalar>());
        spinMax = max(spinMax, returnReduce(c.spinRatioMax, maxOp<scalar>()));
        os  << "      - incoming spin |Omega|a/|V|  = mean "
            << (nSpin > 0 ? spinSum/nSpin : 0) << ", max " << spinMax
            << " (the table answers up to " << RBS_SPIN_TOLERANCE
            << " under auto)" << nl;
    }

    if (s.hits.is_open())
    {
        s.hits.flush();
    }

    if (this->writeTime())
    {
        this->setModelProperty("nHits", nHits);
        this->setModelProperty("nTablePath", nTable);
        this->setModelProperty("nDirectPath", nDirect);
        this->setModelProperty("nRebounded", nRebounded);
        this->setModelProperty("nTrapped", nTrapped);
        this->setModelProperty("nFailed", nFailed);
        this->setModelProperty("nInvalid", nInvalid);
        this->setModelProperty("nOutsideGrid", nOutside);
        this->setModelProperty("massTrapped", mTrapped);
        this->setModelProperty("massFailed", mFailed);
        this->setModelProperty("directModelSeconds", directSeconds);
        this->setModelProperty("nSpinSamples", nSpin);
        this->setModelProperty("spinRatioSum", spinSum);
        this->setModelProperty("spinRatioMax", spinMax);
        s.counters = Counters();
    }
}


// ************************************************************************* //
