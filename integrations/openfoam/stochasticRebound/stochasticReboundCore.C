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

#include "stochasticReboundCore.H"
#include "IOField.H"
#include "OSspecific.H"
#include "Pstream.H"
#include "Time.H"
#include "unitConversion.H"
#include "wallPolyPatch.H"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unordered_set>
#include <utility>

// * * * * * * * * * * * * * * * * * Helpers * * * * * * * * * * * * * * * * //

namespace
{

using namespace Foam;

// The words of a list, comma separated, for a one-line message
std::string joined(const UList<word>& words)
{
    std::string out;
    forAll(words, i)
    {
        out += (i ? ", " : "") + words[i];
    }
    return out;
}

// Refuse the entries of dict that are not in known (a misspelling would
// silently fall back to its default)
void checkEntries
(
    const dictionary& dict,
    const wordList& known,
    const std::string& where
)
{
    for (const word& key : dict.toc())
    {
        if (!known.found(key))
        {
            FatalIOErrorInFunction(dict)
                << "unknown entry " << key << " in " << where.c_str()
                << "; the entries are " << joined(known).c_str()
                << exit(FatalIOError);
        }
    }
}

// The file itself, whatever its spelling (a link, a relative path): the
// key that makes the patches naming one table share it
std::string canonical(const fileName& file)
{
    char* path = ::realpath(file.c_str(), nullptr);
    const std::string key(path ? path : file.c_str());
    std::free(path);
    return key;
}

const char* methodName(int method)
{
    return method == RBS_METHOD_TABLE ? "table"
        : method == RBS_METHOD_DIRECT ? "direct" : "auto";
}

const char* interpolationName(int interpolation)
{
    return interpolation == RBS_INTERPOLATION_STOCHASTIC
        ? "stochastic" : "scaled";
}

// n as an English ordinal (1st, 2nd, 3rd, 4th, 11th, 21st), for the hits
// file's words on hitsEvery
std::string ordinal(uint64_t n)
{
    const uint64_t tens = n % 100;
    const char* suffix =
        tens >= 11 && tens <= 13 ? "th"
      : n % 10 == 1 ? "st"
      : n % 10 == 2 ? "nd"
      : n % 10 == 3 ? "rd"
      : "th";
    return std::to_string(n) + suffix;
}

// A rule's roughness in a few words, for the log and the hits file
std::string roughnessName(const stochasticReboundCore::Rule& rule)
{
    char text[64];
    std::snprintf
    (
        text, sizeof(text), "roughness %g deg%s", rule.roughnessDeg,
        rule.roughnessGiven < 0 ? " (the table's)" : ""
    );
    return text;
}


// A halfSizeFactor: finite and > 0
scalar positiveFactor
(
    const dictionary& dict,
    const word& name,
    scalar value,
    const std::string& where
)
{
    value = dict.getOrDefault<scalar>(name, value);
    if (!(value > 0 && value < VGREAT))
    {
        FatalIOErrorInFunction(dict)
            << where.c_str() << ": " << name << " must be > 0, not " << value
            << exit(FatalIOError);
    }
    return value;
}

} // End anonymous namespace


const char* const Foam::stochasticReboundCore::omegaFieldName =
    "stochasticReboundOmega";

const char* const Foam::stochasticReboundCore::timeFieldName =
    "stochasticReboundTime";

const char* const Foam::stochasticReboundCore::workNormalFieldName =
    "stochasticReboundWorkNormal";

const char* const Foam::stochasticReboundCore::workTangentialFieldName =
    "stochasticReboundWorkTangential";

const char* const Foam::stochasticReboundCore::workHitsFieldName =
    "stochasticReboundHits";


// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

void Foam::stochasticReboundCore::readSettings
(
    Rule& rule,
    const dictionary& dict,
    const string& where
) const
{
    if (dict.found("trapped"))
    {
        const word trapped(dict.get<word>("trapped"));
        if (trapped != "stick" && trapped != "remove")
        {
            FatalIOErrorInFunction(dict)
                << where.c_str() << ": trapped must be stick or remove, not "
                << trapped << exit(FatalIOError);
        }
        rule.removeTrapped = trapped == "remove";
    }

    if (dict.found("interpolation"))
    {
        const word interp(dict.get<word>("interpolation"));
        if (interp != "scaled" && interp != "stochastic")
        {
            FatalIOErrorInFunction(dict)
                << where.c_str()
                << ": interpolation must be scaled or stochastic, not "
                << interp << exit(FatalIOError);
        }
        rule.interpolation =
            interp == "stochastic"
          ? RBS_INTERPOLATION_STOCHASTIC
          : RBS_INTERPOLATION_SCALED;
    }

    if (dict.found("method"))
    {
        const word method(dict.get<word>("method"));
        if (method == "auto")
        {
            rule.method = RBS_METHOD_AUTO;
        }
        else if (method == "table")
        {
            rule.method = RBS_METHOD_TABLE;
        }
        else if (method == "direct")
        {
            rule.method = RBS_METHOD_DIRECT;
        }
        else
        {
            FatalIOErrorInFunction(dict)
                << where.c_str()
                << ": method must be auto, table or direct, not " << method
                << exit(FatalIOError);
        }
    }

    if (dict.found("roughnessDeg"))
    {
        // One token, a number: the library would refuse every hit of a
        // roughness out of range, so it is refused here, before any hit
        ITstream& is = dict.lookup("roughnessDeg");
        const scalar deg =
            is.size() == 1 && is[0].isNumber() ? is[0].number() : -1;
        if (!(deg >= 0 && deg <= RBS_MAX_ROUGHNESS_DEG))
        {
            FatalIOErrorInFunction(dict)
                << where.c_str() << ": roughnessDeg must be in [0, "
                << RBS_MAX_ROUGHNESS_DEG << "] (degrees), not "
                << is.toString().c_str() << exit(FatalIOError);
        }
        rule.roughnessGiven = deg;
    }
}


void Foam::stochasticReboundCore::readSpinRelaxation(const dictionary& coeffs)
{
    memory_ = memoryAuto;
    if (!coeffs.found("spinRelaxation"))
    {
        return;
    }
    // One token: a word (auto, off) or a number (a time in s)
    ITstream& is = coeffs.lookup("spinRelaxation");
    const bool one = is.size() == 1;
    const token& t = is[0];
    if (one && t.isWord() && t.wordToken() == "off")
    {
        memory_ = memoryOff;
    }
    else if (one && t.isWord() && t.wordToken() == "auto")
    {
        memory_ = memoryAuto;
    }
    else if (one && t.isNumber() && t.number() > 0 && t.number() < VGREAT)
    {
        memory_ = memoryTime;
        relaxationTime_ = t.number();
    }
    else
    {
        FatalIOErrorInFunction(coeffs)
            << "spinRelaxation must be auto, off or a time in s > 0, not "
            << is.toString().c_str() << exit(FatalIOError);
    }
}


Foam::fileName Foam::stochasticReboundCore::tablePath
(
    const dictionary& dict,
    const Time& time
)
{
    fileName file(dict.get<fileName>("table"));
    file.expand();
    if (!file.isAbsolute())
    {
        file = time.globalPath()/file;
    }
    return file;
}


std::shared_ptr<const Foam::stochasticReboundCore::Table>
Foam::stochasticReboundCore::openTable
(
    const dictionary& dict,
    const string& where,
    const Time& time,
    TableFiles& tables
) const
{
    const fileName file(tablePath(dict, time));
    const std::string key(canonical(file));
    const auto opened = tables.find(key);
    if (opened != tables.end())
    {
        return opened->second;
    }

    char message[512] = "";
    rbs_table* handle = nullptr;
    const int err =
        rbs_table_open(file.c_str(), &handle, message, sizeof(message));
    if (err != RBS_OK)
    {
        FatalIOErrorInFunction(dict)
            << where.c_str() << ": cannot open the rebound table " << file
            << ": " << rbs_status_string(err) << ": " << message
            << exit(FatalIOError);
    }
    std::shared_ptr<Table> table(new Table());
    table->file = file;
    table->handle.reset(handle, rbs_table_close);

    rbs_table_info info = RBS_TABLE_INFO_INIT;
    rbs_wall_info wall = RBS_WALL_INFO_INIT;
    const int infoErr = rbs_table_info_get(handle, &info);
    const int wallErr = rbs_table_wall(handle, &wall);
    if (infoErr != RBS_OK || wallErr != RBS_OK)
    {
        FatalIOErrorInFunction(dict)
            << where.c_str() << ": cannot read the grids and the wall of the"
            << " rebound table " << file << ": "
            << rbs_status_string(infoErr != RBS_OK ? infoErr : wallErr)
            << exit(FatalIOError);
    }
    table->alpha1Lo = info.alpha1_min_deg;
    table->alpha1Hi = info.alpha1_max_deg;
    table->speedLo = info.speed_min_m_s;
    table->speedHi = info.speed_max_m_s;
    table->lawLo = wall.speed_range_m_s[0];
    table->lawHi = wall.speed_range_m_s[1];
    table->roughness = wall.roughness_deg;
    table->wall =
        wall.name && *wall.name ? wall.name
      : wall.family ? wall.family : "";

    tables[key] = table;
    Info<< "    stochasticRebound: opened the table " << file << " (wall "
        << table->wall.c_str() << ")" << nl;
    return table;
}


void Foam::stochasticReboundCore::readMix
(
    const dictionary& dict,
    Rule& rule,
    const string& where
) const
{
    const Table* table = rule.table.get();
    const rbs_table* t = table ? table->handle.get() : nullptr;
    char message[512] = "";
    rule.mix.reset();
    rule.shapeFactors.clear();
    rule.factorsName.clear();

    // `weights { prism 0.7; tetrahedron { weight 0.3; halfSizeFactor
    // 1.4; } }` or `shape`
    if (dict.found("weights"))
    {
        const dictionary& wd = dict.subDict("weights");
        const wordList names(wd.toc());
        List<const char*> cnames(names.size());
        List<double> weights(names.size());
        List<scalar> factors(names.size(), halfSizeFactor_);
        OStringStream desc;
        forAll(names, i)
        {
            const word& name = names[i];
            cnames[i] = name.c_str();
            const entry& e = *wd.findEntry(name, keyType::LITERAL);
            if (e.isDict())
            {
                // A shape of its own proportion of d: its halfSizeFactor
                const std::string inner
                (
                    "weights entry " + name + " in " + where
                );
                checkEntries(e.dict(), {"weight", "halfSizeFactor"}, inner);
                weights[i] = e.dict().get<scalar>("weight");
                factors[i] = positiveFactor
                (
                    e.dict(), "halfSizeFactor", halfSizeFactor_, inner
                );
            }
            else
            {
                weights[i] = wd.get<scalar>(name);
            }
            desc<< (i ? ", " : "") << name << ' ' << weights[i];
            if (factors[i] != halfSizeFactor_)
            {
                rule.factorsName +=
                    (rule.factorsName.empty() ? "" : ", ") + name + ' '
                  + Foam::name(factors[i]);
            }
        }
        rule.mixName = "weights (" + desc.str() + ")";
        if (t)
        {
            rule.mix.reset
            (
                rbs_mix_new_from_weights
                (
                    t, names.size(), cnames.cdata(), weights.cdata(),
                    message, sizeof(message)
                ),
                rbs_mix_free
            );
            if (!rule.mix)
            {
                FatalIOErrorInFunction(dict)
                    << where.c_str() << ": bad shape weights for the table "
                    << table->file << ": " << message << exit(FatalIOError);
            }
            if (!rule.factorsName.empty())
            {
                // By the table's shape index, which a grain's key gives
                const int n = rbs_table_n_shapes(t);
                rule.shapeFactors.assign(n, halfSizeFactor_);
                for (int k = 0; k < n; ++k)
                {
                    const label i = names.find(rbs_table_shape_name(t, k));
                    if (i >= 0)
                    {
                        rule.shapeFactors[k] = factors[i];
                    }
                }
            }
        }
        return;
    }

    // A mix sized by the table (any number of shapes): one shape, or "mix",
    // equal weights over the table's shapes
    const word shape(dict.getOrDefault<word>("shape", "mix"));
    rule.mixName = shape;
    if (t)
    {
        rule.mix.reset
        (
            rbs_mix_new_from_shape(t, shape.c_str(), message, sizeof(message)),
            rbs_mix_free
        );
        if (!rule.mix)
        {
            FatalIOErrorInFunction(dict)
                << where.c_str() << ": bad shape " << shape
                << " for the table " << table->file << ": " << message
                << exit(FatalIOError);
        }
    }
}


void Foam::stochasticReboundCore::readTableAndMix
(
    Rule& rule,
    const dictionary& dict,
    const dictionary& coeffs,
    const string& where,
    const Time& time,
    TableFiles& tables
) const
{
    if (dict.found("shape") && dict.found("weights"))
    {
        FatalIOErrorInFunction(dict)
            << "shape and weights are both given in " << where.c_str()
            << ": give one of them (weights would take precedence unseen)"
            << exit(FatalIOError);
    }
    const dictionary& tableDict = dict.found("table") ? dict : coeffs;
    if (!tableDict.found("table"))
    {
        FatalIOErrorInFunction(dict)
            << where.c_str() << ": no table: give one here or in "
            << coeffs.dictName() << exit(FatalIOError);
    }
    rule.table = openTable(tableDict, where, time, tables);
    readMix
    (
        dict.found("shape") || dict.found("weights") ? dict : coeffs,
        rule,
        where
    );
    rule.roughnessDeg =
        rule.roughnessGiven >= 0 ? rule.roughnessGiven : rule.table->roughness;
}


Foam::stochasticReboundCore::Rule Foam::stochasticReboundCore::entryRule
(
    const dictionary& dict,
    const Rule& global,
    const dictionary& coeffs,
    const string& where,
    const Time& time,
    TableFiles& tables
) const
{
    static const wordList types
    ({"stochasticRebound", "rebound", "stick", "escape"});
    const word type(dict.getOrDefault<word>("type", word::null));
    if (!types.found(type))
    {
        FatalIOErrorInFunction(dict)
            << where.c_str() << ": "
            << (type.empty() ? "no type" : "type " + type + " is unknown")
               .c_str()
            << "; the types are " << joined(types).c_str()
            << exit(FatalIOError);
    }

    Rule rule;
    if (type == "stochasticRebound")
    {
        checkEntries
        (
            dict,
            {
                "type", "table", "shape", "weights", "method",
                "interpolation", "trapped", "roughnessDeg"
            },
            where
        );
        rule = global;
        readSettings(rule, dict, where);
        readTableAndMix(rule, dict, coeffs, where, time, tables);
    }
    else if (type == "rebound")
    {
        checkEntries(dict, {"type", "e", "mu"}, where);
        // localInteraction's defaults: e 1, mu 0
        auto fraction = [&dict, &where](const word& name, scalar value)
        {
            value = dict.getOrDefault<scalar>(name, value);
            if (!(value >= 0 && value <= 1))
            {
                FatalIOErrorInFunction(dict)
                    << where.c_str() << ": " << name
                    << " must be in [0, 1], not " << value
                    << exit(FatalIOError);
            }
            return value;
        };
        rule.type = ruleRebound;
        rule.e = fraction("e", 1);
        rule.mu = fraction("mu", 0);
    }
    else
    {
        checkEntries(dict, {"type"}, where);
        rule.type = type == "stick" ? ruleStick : ruleEscape;
    }
    return rule;
}


void Foam::stochasticReboundCore::readRules
(
    const dictionary& coeffs,
    const polyMesh& mesh
)
{
    const Time& time = mesh.time();
    const polyBoundaryMesh& bMesh = mesh.boundaryMesh();
    const label nPatches = bMesh.nNonProcessor();
    const bool listed = coeffs.found("patches");
    TableFiles tables;

    // The global rule: what every wall does without a patches list, the
    // defaults of the entries with one (which need no global table)
    const string global(coeffs.dictName());
    List<Rule> rules(1);
    readSettings(rules[0], coeffs, global);
    if (!listed)
    {
        readTableAndMix(rules[0], coeffs, coeffs, global, time, tables);
    }
    else
    {
        // Opened when an entry takes it: a table may be large
        readMix(coeffs, rules[0], global);
        if (coeffs.found("table") && !isFile(tablePath(coeffs, time)))
        {
            FatalIOErrorInFunction(coeffs)
                << global.c_str() << ": no rebound table "
                << tablePath(coeffs, time) << exit(FatalIOError);
        }
    }
    mixName_ = rules[0].mixName;

    // Constraint patches keep their own behaviour: no entry names them
    patchRule_.setSize(nPatches, -1);
    patchNames_.setSize(nPatches);
    DynamicList<word> nameable;
    for (label patchi = 0; patchi < nPatches; ++patchi)
    {
        const polyPatch& pp = bMesh[patchi];
        patchNames_[patchi] = pp.name();
        if (!pp.coupled() && !polyPatch::constraintType(pp.type()))
        {
            nameable.append(pp.name());
        }
    }

    if (listed)
    {
        if (coeffs.isDict("patches"))
        {
            FatalIOErrorInFunction(coeffs)
                << "patches in " << global.c_str() << " must be a list, as"
                << " localInteraction's: patches ( name { type ...; } ... );"
                << exit(FatalIOError);
        }
        for (const entry& e : PtrList<entry>(coeffs.lookup("patches")))
        {
            const keyType& key = e.keyword();
            const string where("patches entry " + key + " in " + global);
            if (!e.isDict())
            {
                FatalIOErrorInFunction(coeffs)
                    << where.c_str() << " must be a dictionary: " << key
                    << " { type stochasticRebound; ... }"
                    << exit(FatalIOError);
            }
            rules.append
            (
                entryRule(e.dict(), rules[0], coeffs, where, time, tables)
            );

            // localInteraction's matching: names, groups and regexes; the
            // first entry that names a patch applies to it
            label matched = 0;
            for (const label patchi : bMesh.indices(key, true))
            {
                if (patchi < nPatches && nameable.found(bMesh[patchi].name()))
                {
                    ++matched;
                    if (patchRule_[patchi] < 0)
                    {
                        patchRule_[patchi] = rules.size() - 1;
                    }
                }
            }
            if (!matched)
            {
                FatalIOErrorInFunction(e.dict())
                    << where.c_str() << ": no patch or patch group is named "
                    << key << "; the patches are " << joined(nameable).c_str()
                    << " and the groups "
                    << joined(bMesh.groupPatchIDs().sortedToc()).c_str()
                    << exit(FatalIOError);
            }
        }
    }

    // The patches no entry names: walls take the global rule (an error
    // under a patches list: each wall's behaviour must be said); open
    // patches keep OpenFOAM's default, counted
    DynamicList<word> unnamedWalls;
    label openRule = -1;
    for (label patchi = 0; patchi < nPatches; ++patchi)
    {
        const polyPatch& pp = bMesh[patchi];
        if (patchRule_[patchi] >= 0 || !nameable.found(pp.name()))
        {
            continue;
        }
        if (isA<wallPolyPatch>(pp))
        {
            patchRule_[patchi] = 0;
            unnamedWalls.append(pp.name());
        }
        else
        {
            if (openRule < 0)
            {
                openRule = rules.size();
                rules.append(Rule());
                rules[openRule].type = ruleOpen;
            }
            patchRule_[patchi] = openRule;
        }
    }
    if (listed && unnamedWalls.size())
    {
        FatalIOErrorInFunction(coeffs)
            << "wall patch " << joined(unnamedWalls).c_str()
            << " is named by no entry of patches in " << global.c_str()
            << ": say what each wall does (type stochasticRebound, rebound,"
            << " stick or escape)" << exit(FatalIOError);
    }

    // The global table in the hits file's header, if a patch draws from it
    if
    (
        coeffs.found("table")
     && tables.count(canonical(tablePath(coeffs, time)))
    )
    {
        tableFile_ = tablePath(coeffs, time);
    }
    rules_.reset(new List<Rule>(std::move(rules)));
}


std::string Foam::stochasticReboundCore::describe
(
    const Rule& rule,
    bool full
) const
{
    char text[1536];
    switch (rule.type)
    {
        case ruleDrawn:
        {
            const Table& t = *rule.table;
            if (!full)
            {
                return "stochasticRebound, wall " + t.wall;
            }
            const int nShapes = rbs_table_n_shapes(t.handle.get());
            char tolerance[64] = "";
            if (rule.method == RBS_METHOD_AUTO)
            {
                std::snprintf
                (
                    tolerance, sizeof(tolerance), " (spin tolerance %g)",
                    RBS_SPIN_TOLERANCE
                );
            }
            const std::string factors
            (
                rule.factorsName.empty()
              ? ""
              : ", halfSizeFactor per shape " + rule.factorsName
            );
            std::snprintf
            (
                text, sizeof(text),
                "stochasticRebound, wall %s, table %s (%d shape%s, alpha1 "
                "%g-%g deg, |V| %g-%g m/s), shape %s%s, method %s%s, "
                "interpolation %s, trapped parcels %s, %s",
                t.wall.c_str(), t.file.c_str(), nShapes,
                nShapes == 1 ? "" : "s", t.alpha1Lo, t.alpha1Hi,
                t.speedLo, t.speedHi, rule.mixName.c_str(), factors.c_str(),
                methodName(rule.method), tolerance,
                interpolationName(rule.interpolation),
                rule.removeTrapped ? "removed" : "stick",
                roughnessName(rule).c_str()
            );
            return text;
        }
        case ruleRebound:
        {
            std::snprintf
            (
                text, sizeof(text), "rebound, e %g, mu %g", rule.e, rule.mu
            );
            return text;
        }
        case ruleStick:
            return "stick";
        case ruleEscape:
            return "escape";
        default:
            return "escape (open patch no entry names: OpenFOAM's default)";
    }
}


std::string Foam::stochasticReboundCore::describeMemory() const
{
    if (ownSpin_)
    {
        return "not used: the parcels carry their own spin";
    }
    char text[256];
    switch (memory_)
    {
        case memoryOff:
            return "off: every hit arrives without spin";
        case memoryTime:
            std::snprintf
            (
                text, sizeof(text),
                "%g s: Omega = Omega+ exp(-dt/tau_r) from each drawn rebound,"
                " tau_r = %g s", relaxationTime_, relaxationTime_
            );
            return text;
        default:
            return "auto: Omega = Omega+ exp(-dt/tau_r) from each drawn"
                " rebound, tau_r = rho_p (2a)^2/(60 mu), mu the gas"
                " viscosity at the parcel's cell";
    }
}


bool Foam::stochasticReboundCore::rememberedSpin
(
    const Parcel& parcel,
    scalar a,
    vector& Omega
) const
{
    const auto& spins = state_->spins;
    const auto found = spins.find(parcelKey(parcel.origProc, parcel.origId));
    if (found == spins.end())
    {
        return false;
    }
    // Stokes rotation of a sphere of radius a: torque 8 pi mu a^3 Omega
    // against the moment of inertia 8/15 pi rho a^5
    const scalar tau =
        memory_ == memoryTime
      ? relaxationTime_
      : parcel.rho*sqr(2*a)/(60*parcel.mu);
    // MPPIC's correction track starts a step's fraction again: never < 0
    const scalar dt = max(parcel.time - found->second.time, scalar(0));
    Omega = found->second.Omega*std::exp(-dt/tau);
    return true;
}


void Foam::stochasticReboundCore::recordHit
(
    const Parcel& parcel,
    const polyPatch& pp,
    const Rule& rule,
    const double V[3],
    const double Omega[3],
    const double n[3],
    double a,
    int status,
    int path,
    const double Vout[3],
    const double Wout[3],
    scalar spinRatio,
    double u0,
    int64_t key,
    int shape,
    double workNormal,
    double workTangential
)
{
    State& s = *state_;
    if (!s.hits.is_open() || s.nRecorded >= maxHitRecords_)
    {
        return;
    }
    // hitsEvery k keeps the 1st, (k+1)-th, ... hit of those this rank records
    if (s.nRecordable++ % uint64_t(hitsEvery_) != 0)
    {
        return;
    }
    ++s.nRecorded;

    // The grain: its shape under grain kept (empty for a new grain per
    // hit; the result's, else, for a hit refused, the key's), and b/a, c/b
    // and the hand where the direct path fixed them (NaN on the table path,
    // which draws them from the shape's law)
    const char* shapeName = "";
    double ratioBa = NAN, ratioCb = NAN, hand = NAN;
    const char* interaction = "rebound";
    std::string wall;
    if (rule.type == ruleDrawn)
    {
        interaction = "stochasticRebound";
        const rbs_table* table = rule.table->handle.get();
        // The reader splits rows at commas: a wall named with one keeps it
        // as a semicolon
        wall = rule.table->wall;
        std::replace(wall.begin(), wall.end(), ',', ';');
        if (key >= 0)
        {
            int grainShape = shape;
            if (grainShape < 0 || path == RBS_PATH_DIRECT)
            {
                rbs_grain grain = RBS_GRAIN_INIT;
                if
                (
                    rbs_grain_info(table, rule.mix.get(), key, &grain)
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
                shapeName = rbs_table_shape_name(table, grainShape);
            }
        }
    }

    const vector& Uwall = parcel.Uwall;
    char line[1280];
    std::snprintf
    (
        line, sizeof(line),
        "%.9g,%d,%s,%d,%d,%.9g,%.9g,"
        "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
        "%.9g,%.9g,%.9g,"
        "%d,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.9g,%.17g,"
        "%lld,%s,%.17g,%.17g,%g,%s,%s\n",
        pp.boundaryMesh().mesh().time().value(),
        int(Pstream::myProcNo()), pp.name().c_str(),
        int(parcel.origProc), int(parcel.origId), parcel.d, a,
        V[0], V[1], V[2], Omega[0], Omega[1], Omega[2], n[0], n[1], n[2],
        Uwall.x(), Uwall.y(), Uwall.z(),
        status, path, Vout[0], Vout[1], Vout[2],
        Wout[0], Wout[1], Wout[2], spinRatio, u0,
        static_cast<long long>(key), shapeName, ratioBa, ratioCb, hand,
        interaction, wall.c_str()
    );
    s.hits << line;

    std::snprintf
    (
        line, sizeof(line), "%d,%d,%s,%d,%.17g,%.17g,%.17g\n",
        int(parcel.origProc), int(parcel.origId), pp.name().c_str(),
        int(parcel.face), parcel.mass, workNormal, workTangential
    );
    s.work << line;
}


void Foam::stochasticReboundCore::makeWorkFields
(
    const fvMesh& mesh,
    const word& cloudName
)
{
    // As particleErosion's Q: named after the cloud, zero inside, values
    // on the patches' faces, read back at a restart's start time
    const Time& time = mesh.time();
    label nRead = 0;
    auto field = [&](const char* name, const dimensionSet& dims)
    {
        IOobject io
        (
            cloudName + ":" + name, time.timeName(), mesh,
            IOobject::READ_IF_PRESENT, IOobject::AUTO_WRITE
        );
        nRead += io.typeHeaderOk<volScalarField>(true);
        return std::unique_ptr<volScalarField>
        (
            new volScalarField(io, mesh, dimensionedScalar(dims, Zero))
        );
    };
    State& s = *state_;
    s.workNormal = field(workNormalFieldName, dimEnergy);
    s.workTangential = field(workTangentialFieldName, dimEnergy);
    s.workHits = field(workHitsFieldName, dimless);
    if (returnReduce(nRead, maxOp<label>()))
    {
        Info<< "    stochasticRebound: read the work on the walls ("
            << s.workNormal->name() << ", " << s.workTangential->name()
            << ", " << s.workHits->name() << ") at time "
            << time.timeName() << nl;
    }
}


void Foam::stochasticReboundCore::addWork
(
    const polyPatch& pp,
    const Parcel& parcel,
    double Wn,
    double Wt,
    label* counts
)
{
    State& s = *state_;
    if (!std::isfinite(Wn) || !std::isfinite(Wt))
    {
        // A table of format 4.0 holds no work: one NaN would make the face's
        // sum NaN for the rest of the run
        ++counts[pcNoWork];
        ++s.counters.noWork;
        return;
    }
    const label patchi = pp.index();
    const label facei = parcel.face;
    s.workNormal->boundaryFieldRef()[patchi][facei] += parcel.mass*Wn;
    s.workTangential->boundaryFieldRef()[patchi][facei] += parcel.mass*Wt;
    s.workHits->boundaryFieldRef()[patchi][facei] += 1;
    s.counters.workNormal += parcel.mass*Wn;
    s.counters.workTangential += parcel.mass*Wt;
    s.patchWork[2*patchi] += Wn;
    s.patchWork[2*patchi + 1] += Wt;
}


void Foam::stochasticReboundCore::drawRebound
(
    const polyPatch& pp,
    const Rule& rule,
    const Parcel& parcel,
    label* counts,
    Outcome& out
)
{
    State& s = *state_;
    Counters& c = s.counters;
    const Table& table = *rule.table;
    const rbs_table* t = table.handle.get();

    const vector Vin(parcel.U - parcel.Uwall);
    const scalar nMag = mag(parcel.nw);

    // grain kept: the parcel's ids, born with it, carried across ranks and
    // restarts, give its key; perHit: RBS_NO_KEY, a new grain per hit
    const int64_t key =
        keepGrain_
      ? rbs_grain_key
        (
            grainSeed_, uint64_t(parcel.origProc), uint64_t(parcel.origId)
        )
      : RBS_NO_KEY;

    // The half-size: the grain's shape's own factor where weights give one
    // (grain kept: the key fixes the shape before the draw)
    scalar factor = halfSizeFactor_;
    if (!rule.shapeFactors.empty())
    {
        rbs_grain grain = RBS_GRAIN_INIT;
        if (rbs_grain_info(t, rule.mix.get(), key, &grain) == RBS_OK)
        {
            factor = rule.shapeFactors[grain.shape];
        }
    }
    const scalar a = factor*0.5*parcel.d;

    // Ω⁻: the parcel's own, else the remembered one, relaxed over the
    // flight since its last rebound
    vector Win(parcel.Omega);
    const bool remembered = remembers() && rememberedSpin(parcel, a, Win);
    c.remembered += remembered;

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
        hit.n[0] = -parcel.nw.x()/nMag;
        hit.n[1] = -parcel.nw.y()/nMag;
        hit.n[2] = -parcel.nw.z()/nMag;
    }
    hit.a = a;
    hit.grain_key = key;
    double u[RBS_U_PER_DRAW];
    rbs_rng_fill(&s.rng, u, RBS_U_PER_DRAW);
    hit.u = u;

    rbs_options options = RBS_OPTIONS_INIT;
    options.method = rule.method;
    options.interpolation = rule.interpolation;
    options.roughness_deg = rule.roughnessDeg;

    // The path is a pure function of the state: learnt before the draw,
    // so the clock runs around the direct model's calls only. On a rough
    // wall each facet hit takes its own path: the last one's is counted
    // (a hit that hits again ends on the direct model under auto), and the
    // clock runs around every hit
    const bool rough = rule.roughnessDeg > 0;
    const int meanPath = rbs_rebound_path(t, &hit, &options);
    std::chrono::steady_clock::time_point t0;
    if (rough || meanPath == RBS_PATH_DIRECT)
    {
        t0 = std::chrono::steady_clock::now();
    }
    rbs_result result = RBS_RESULT_INIT;
    const int status = rbs_rebound(t, rule.mix.get(), &hit, &options, &result);
    const int path =
        rough && result.path != RBS_PATH_NONE ? result.path : meanPath;
    if (path == RBS_PATH_DIRECT)
    {
        c.directSeconds += std::chrono::duration<double>
        (
            std::chrono::steady_clock::now() - t0
        ).count();
        ++c.directPath;
        ++counts[pcDirect];
    }
    else if (path == RBS_PATH_TABLE)
    {
        ++c.tablePath;
        ++counts[pcTable];
    }

    ++c.hits;
    counts[pcHitAgain] += result.wall_hits > 1;
    counts[pcAtCap] += result.wall_hits >= RBS_MAX_WALL_HITS;

    const scalar speed = mag(Vin);
    const scalar spinRatio = speed > 0 ? mag(Win)*a/speed : 0;
    if (ownSpin_ || remembers())
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
        const bool below = speed < table.speedLo;
        const bool above = speed > table.speedHi;
        const bool alpha1Out =
            alpha1 < table.alpha1Lo || alpha1 > table.alpha1Hi;
        counts[pcSpeedBelow] += below;
        counts[pcSpeedAbove] += above;
        counts[pcAlpha1Outside] += alpha1Out;
        counts[pcOutsideLaw] += speed < table.lawLo || speed > table.lawHi;
        c.outsideGrid += below || above || alpha1Out;
    }

    if (status != RBS_INVALID)
    {
        addWork
        (
            pp, parcel, result.wall_work_normal, result.wall_work_tangential,
            counts
        );
    }

    const uint64_t parcelId = parcelKey(parcel.origProc, parcel.origId);
    switch (status)
    {
        case RBS_OK:
        {
            ++c.rebounded;
            ++counts[pcRebounded];
            out.fate = fateRebound;
            out.U = vector(result.V[0], result.V[1], result.V[2])
              + parcel.Uwall;
            out.Omega =
                vector(result.Omega[0], result.Omega[1], result.Omega[2]);
            if (remembers())
            {
                s.spins[parcelId] = Spin{out.Omega, parcel.time};
            }
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
                ++counts[pcTrapped];
                c.trappedMass += parcel.mass;
            }
            else
            {
                ++c.failed;
                ++counts[pcFailed];
                c.failedMass += parcel.mass;
            }
            // stick: kept, inactive, at rest on the wall; remove: deleted
            ++counts[rule.removeTrapped ? pcRemoved : pcStuck];
            out.fate = rule.removeTrapped ? fateRemoved : fateStopped;
            s.spins.erase(parcelId);
            break;
        }
        default:
        {
            // Not moving into the wall (or a degenerate normal): the stock
            // rebound leaves such a parcel's velocity, and spin, as it is
            ++c.invalid;
            ++counts[pcInvalid];
            out.fate = fateUnchanged;
            break;
        }
    }

    if (s.hits.is_open())
    {
        recordHit
        (
            parcel, pp, rule, hit.V, hit.Omega, hit.n, a, result.status,
            path, result.V, result.Omega, spinRatio, u[0], hit.grain_key,
            result.shape, result.wall_work_normal,
            result.wall_work_tangential
        );
    }
}


void Foam::stochasticReboundCore::stockRebound
(
    const polyPatch& pp,
    const Rule& rule,
    const Parcel& parcel,
    label* counts,
    Outcome& out
)
{
    // localInteraction's rebound, operation for operation
    const vector& nw = parcel.nw;
    const vector& Up = parcel.Uwall;
    const vector Vin(parcel.U - Up);
    vector U(parcel.U);
    U -= Up;
    const scalar Un = U & nw;
    const vector Ut = U - Un*nw;
    if (Un > 0)
    {
        U -= (1.0 + rule.e)*Un*nw;
    }
    U -= rule.mu*Ut;
    U += Up;
    ++counts[pcRebounded];
    // Ω unchanged: a remembered spin relaxes on from the last drawn rebound
    out.fate = fateRebound;
    out.U = U;
    out.Omega = parcel.Omega;

    if (state_->hits.is_open())
    {
        // Recorded in the model's terms: n into the gas, Ω unchanged, no
        // draw (path -1, u0 nan), no grain, no work (not the model's)
        const scalar nMag = mag(nw);
        const vector n(nMag > 0 ? vector(-nw/nMag) : vector(Zero));
        const scalar a = halfSizeFactor_*0.5*parcel.d;
        vector W(parcel.Omega);
        if (remembers())
        {
            rememberedSpin(parcel, a, W);
        }
        const vector Vout(U - Up);
        const scalar speed = mag(Vin);
        const double V[3] = {Vin.x(), Vin.y(), Vin.z()};
        const double N[3] = {n.x(), n.y(), n.z()};
        const double Om[3] = {W.x(), W.y(), W.z()};
        const double Vo[3] = {Vout.x(), Vout.y(), Vout.z()};
        recordHit
        (
            parcel, pp, rule, V, Om, N, a, RBS_OK, RBS_PATH_NONE, Vo, Om,
            speed > 0 ? mag(W)*a/speed : 0, NAN, RBS_NO_KEY, -1, NAN, NAN
        );
    }
}


void Foam::stochasticReboundCore::writeSpins
(
    const objectRegistry& cloud,
    const labelUList& origProc,
    const labelUList& origId
) const
{
    // One value per parcel in the cloud's order, as the parcels' own fields
    // (decomposePar and reconstructPar carry them); zero: none remembered
    const label n = origProc.size();
    const auto& spins = state_->spins;
    auto io = [&cloud](const char* name)
    {
        return IOobject
        (
            name, cloud.time().timeName(), cloud, IOobject::NO_READ,
            IOobject::NO_WRITE, false
        );
    };
    IOField<vector> Omega(io(omegaFieldName), n);
    IOField<scalar> time(io(timeFieldName), n);
    forAll(origProc, i)
    {
        const auto found = spins.find(parcelKey(origProc[i], origId[i]));
        Omega[i] = found == spins.end() ? vector(Zero) : found->second.Omega;
        time[i] = found == spins.end() ? scalar(0) : found->second.time;
    }
    // As the cloud writes its fields: only where it has parcels
    Omega.write(n > 0);
    time.write(n > 0);
}


void Foam::stochasticReboundCore::readSpins(const objectRegistry& cloud)
{
    // The parcels' ids are read after the models are made: read them here
    // from the time folder, in the order the fields were written in
    auto io = [&cloud](const word& name)
    {
        return IOobject
        (
            name, cloud.time().timeName(), cloud, IOobject::MUST_READ,
            IOobject::NO_WRITE, false
        );
    };
    label nRead = 0;
    IOobject omegaIO(io(omegaFieldName));
    if (omegaIO.typeHeaderOk<IOField<vector>>(true))
    {
        const IOField<vector> Omega(omegaIO);
        const IOField<scalar> time(io(timeFieldName));
        const IOField<label> origProc(io("origProcId"));
        const IOField<label> origId(io("origId"));
        if
        (
            time.size() != Omega.size() || origProc.size() != Omega.size()
         || origId.size() != Omega.size()
        )
        {
            FatalErrorInFunction
                << omegaIO.objectPath() << ", " << timeFieldName
                << ", origProcId and origId hold " << Omega.size() << ", "
                << time.size() << ", " << origProc.size() << " and "
                << origId.size() << " values: not one per parcel"
                << exit(FatalError);
        }
        forAll(Omega, i)
        {
            if (mag(Omega[i]) > 0)
            {
                state_->spins[parcelKey(origProc[i], origId[i])] =
                    Spin{Omega[i], time[i]};
                ++nRead;
            }
        }
    }
    reduce(nRead, sumOp<label>());
    if (nRead)
    {
        Info<< "    stochasticRebound: read the remembered spins of " << nRead
            << " parcels (" << omegaFieldName << ", " << timeFieldName
            << ")" << nl;
    }
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::stochasticReboundCore::stochasticReboundCore
(
    const dictionary& coeffs,
    const fvMesh& mesh,
    const objectRegistry& cloud,
    bool ownSpin,
    bool steady
)
:
    tableFile_(),
    mixName_(),
    rules_(),
    patchRule_(),
    halfSizeFactor_(1),
    seed_(0),
    keepGrain_(true),
    grainSeed_(0),
    writeHits_(coeffs.getOrDefault<bool>("writeHits", false)),
    maxHitRecords_(coeffs.getOrDefault<label>("maxHitRecords", 1000000)),
    hitsEvery_(1),
    ownSpin_(ownSpin),
    steady_(steady),
    memory_(memoryAuto),
    relaxationTime_(0),
    state_(new State())
{
    // The entries of this model and of its base classes
    static const wordList known
    ({
        "table", "shape", "weights", "halfSizeFactor", "trapped", "seed",
        "interpolation", "method", "grain", "grainSeed", "writeHits",
        "maxHitRecords", "hitsEvery", "patches", "spinRelaxation",
        "roughnessDeg", "U", "writePrecision", "writeToFile", "useUserTime", "defaultCoeffs"
    });
    checkEntries(coeffs, known, std::string(coeffs.dictName()));
    if (maxHitRecords_ < 0)
    {
        FatalIOErrorInFunction(coeffs)
            << "maxHitRecords must be >= 0, not " << maxHitRecords_
            << exit(FatalIOError);
    }
    if (coeffs.found("hitsEvery"))
    {
        // One token, a whole number (3.0 is 3): get<label> refuses 2.5
        // without naming the range
        ITstream& is = coeffs.lookup("hitsEvery");
        const scalar every =
            is.size() == 1 && is[0].isNumber() ? is[0].number() : 0;
        if (!(every >= 1 && every <= labelMax && every == std::floor(every)))
        {
            FatalIOErrorInFunction(coeffs)
                << "hitsEvery must be an integer >= 1, not "
                << is.toString().c_str() << exit(FatalIOError);
        }
        hitsEvery_ = label(every);
    }

    halfSizeFactor_ = positiveFactor
    (
        coeffs, "halfSizeFactor", 1, std::string(coeffs.dictName())
    );

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

    readSpinRelaxation(coeffs);

    readRules(coeffs, mesh);
    const List<Rule>& rules = *rules_;
    for (const Rule& rule : rules)
    {
        if (!keepGrain_ && !rule.factorsName.empty())
        {
            // perHit draws the shape inside the hit, after a is set
            FatalIOErrorInFunction(coeffs)
                << "halfSizeFactor per shape in weights needs grain kept,"
                << " not perHit: a new grain's shape is drawn after its"
                << " half-size is set" << exit(FatalIOError);
        }
    }
    state_->patchCounts.setSize(nPatchCounts*patchRule_.size(), Zero);
    state_->patchWork.setSize(2*patchRule_.size(), Zero);
    makeWorkFields(mesh, cloud.name());

    // Rank r draws stream r of the seed: no two ranks share draws
    const label stream = Pstream::myProcNo();
    rbs_rng_seed_stream(&state_->rng, seed_, uint64_t(stream));

    if (remembers() && !steady_)
    {
        readSpins(cloud);
    }

    if (writeHits_)
    {
        const fileName dir
        (
            mesh.time().globalPath()/"postProcessing"/"lagrangian"
           /cloud.name()/"stochasticRebound"
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
            << stream << ", table "
            << (tableFile_.empty() ? "none" : tableFile_.c_str()) << ", mix "
            << mixName_.c_str() << ", halfSizeFactor " << halfSizeFactor_
            << ", interpolation " << interpolationName(rules[0].interpolation)
            << ", method " << methodName(rules[0].method)
            << ", spin tolerance " << RBS_SPIN_TOLERANCE
            << ", grain " << grainMode.c_str();
        if (keepGrain_)
        {
            state_->hits << " (key seed " << grainSeed_ << ")";
        }
        state_->hits << "\n# ";
        if (hitsEvery_ > 1)
        {
            // A reader of the file must know it holds a sample
            const uint64_t k = hitsEvery_;
            state_->hits
                << "Every " << ordinal(k) << " hit (hitsEvery " << k
                << "): the 1st, " << ordinal(k + 1) << ", "
                << ordinal(2*k + 1) << ", ... of the hits this rank"
                   " would record. ";
        }
        state_->hits
            << "V: incident velocity relative to the wall, Win: incident"
               " angular velocity (colliding parcels' own; else the spin"
               " remembered from the parcel's last rebound, or 0), n: unit"
               " normal into the gas, Uw: wall velocity, path: 0 table, 1"
               " direct model, -1 invalid or stock (on a rough wall, the"
               " last of its wall hits), Vout/Wout: rebound"
               " velocity (relative to the wall) and angular velocity,"
               " spin_ratio: |Win| a/|V|, u0: first uniform of the draw, key:"
               " the parcel's grain key (-1: a new grain per hit), shape: its"
               " shape (empty: drawn per hit), ratio_ba/ratio_cb/hand: its"
               " b/a, c/b and hand on the direct path (nan: the table path or"
               " not random), interaction: stochasticRebound or rebound (the"
               " stock rebound; stick and escape hits are counted, not"
               " recorded), wall: the wall of the patch's table. Spin memory: "
            << describeMemory().c_str() << ". Patches:";
        const char* separator = " ";
        forAll(patchRule_, patchi)
        {
            if (patchRule_[patchi] >= 0)
            {
                state_->hits
                    << separator << patchNames_[patchi].c_str() << " = "
                    << describe(rules[patchRule_[patchi]], true);
                separator = "; ";
            }
        }
        state_->hits << "\n"
            << "time,rank,patch,origProc,origId,d,a,Vx,Vy,Vz,Winx,Winy,Winz,"
               "nx,ny,nz,Uwx,Uwy,Uwz,status,path,Voutx,Vouty,Voutz,Wx,Wy,Wz,"
               "spin_ratio,u0,key,shape,ratio_ba,ratio_cb,hand,interaction,"
               "wall\n";

        // The work in a file of its own: the hits file keeps the columns
        // tablegen/study/hit_records.py reads for both adapters
        const fileName workFile
        (
            dir/("wallWork_" + Foam::name(stream) + ".csv")
        );
        state_->work.open(workFile.c_str(), std::ios::out | std::ios::trunc);
        if (!state_->work)
        {
            FatalErrorInFunction
                << "Cannot write " << workFile << exit(FatalError);
        }
        state_->work
            << "# stochasticRebound wall work: row i is row i of hits_"
            << stream << ".csv. face: the face hit (its index in the patch),"
               " mass: the parcel's particles' (nParticle*mass, kg), Wn/Wt:"
               " the work of the hit on the wall per unit particle mass,"
               " normal and tangential (J/kg, rbs_result.wall_work_normal and"
               " wall_work_tangential; nan: none, for an invalid hit, a stock"
               " rebound or a table of format 4.0)\n"
            << "origProc,origId,patch,face,mass,Wn,Wt\n";
    }

    Info<< "    stochasticRebound: a = " << halfSizeFactor_ << "*d/2, seed "
        << seed_ << " (rank r draws stream r), grain " << grainMode
        << (
               keepGrain_
             ? " (a parcel's key from grainSeed, origProc, origId; grainSeed "
             : " (a new grain from the mix at every hit"
           );
    if (keepGrain_)
    {
        Info<< grainSeed_;
    }
    Info<< ")" << nl
        << "    stochasticRebound: spin memory "
        << describeMemory().c_str()
        << (
               remembers() && steady_
             ? " (steady tracking: over each iteration's tracks)" : ""
           )
        << nl;
    forAll(patchRule_, patchi)
    {
        if (patchRule_[patchi] >= 0)
        {
            Info<< "        " << patchNames_[patchi] << ": "
                << describe(rules[patchRule_[patchi]], true).c_str() << nl;
        }
    }
    Info<< endl;
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

bool Foam::stochasticReboundCore::correct
(
    const polyPatch& pp,
    const Parcel& parcel,
    Outcome& out
)
{
    const label patchi = pp.index();
    const label ruleI = patchi < patchRule_.size() ? patchRule_[patchi] : -1;
    if (ruleI < 0)
    {
        // A constraint patch: its own behaviour
        return false;
    }
    const Rule& rule = (*rules_)[ruleI];
    label* counts = state_->patchCounts.data() + nPatchCounts*patchi;
    ++counts[pcHits];

    switch (rule.type)
    {
        case ruleDrawn:
        {
            drawRebound(pp, rule, parcel, counts, out);
            return true;
        }
        case ruleRebound:
        {
            stockRebound(pp, rule, parcel, counts, out);
            return true;
        }
        case ruleStick:
        {
            // localInteraction's stick and escape
            ++counts[pcStuck];
            out.fate = fateStopped;
            state_->spins.erase(parcelKey(parcel.origProc, parcel.origId));
            return true;
        }
        case ruleEscape:
        {
            ++counts[pcEscaped];
            out.fate = fateRemoved;
            state_->spins.erase(parcelKey(parcel.origProc, parcel.origId));
            return true;
        }
        default:
        {
            // An open patch no entry names: OpenFOAM deletes the parcel
            // (particle::hitBoundaryFace), counted here
            ++counts[pcEscaped];
            state_->spins.erase(parcelKey(parcel.origProc, parcel.origId));
            return false;
        }
    }
}


void Foam::stochasticReboundCore::endOfStep
(
    const objectRegistry& cloud,
    const labelUList& origProc,
    const labelUList& origId,
    bool writeTime
)
{
    State& s = *state_;
    if (steady_)
    {
        // Steady tracking renumbers the next iteration's parcels from 0
        s.spins.clear();
        return;
    }

    std::unordered_set<uint64_t> here(2*origProc.size());
    forAll(origProc, i)
    {
        here.insert(parcelKey(origProc[i], origId[i]));
    }

    // The spins of parcels no longer on this rank: they left the domain, or
    // crossed to another rank, which takes the spin over below
    DynamicList<label> goneIds;
    DynamicList<vector> goneOmega;
    DynamicList<scalar> goneTime;
    for (auto it = s.spins.begin(); it != s.spins.end();)
    {
        if (here.count(it->first))
        {
            ++it;
            continue;
        }
        goneIds.append(label(it->first >> 32));
        goneIds.append(label(uint32_t(it->first)));
        goneOmega.append(it->second.Omega);
        goneTime.append(it->second.time);
        it = s.spins.erase(it);
    }

    if (Pstream::parRun() && returnReduce(goneTime.size(), sumOp<label>()))
    {
        const label me = Pstream::myProcNo();
        List<labelList> ids(Pstream::nProcs());
        List<vectorField> omegas(Pstream::nProcs());
        List<scalarField> times(Pstream::nProcs());
        ids[me].transfer(goneIds);
        omegas[me].transfer(goneOmega);
        times[me].transfer(goneTime);
        Pstream::gatherList(ids);
        Pstream::scatterList(ids);
        Pstream::gatherList(omegas);
        Pstream::scatterList(omegas);
        Pstream::gatherList(times);
        Pstream::scatterList(times);
        forAll(ids, proci)
        {
            if (proci == me)
            {
                continue;
            }
            forAll(times[proci], i)
            {
                const uint64_t key =
                    parcelKey(ids[proci][2*i], ids[proci][2*i + 1]);
                if (!here.count(key))
                {
                    continue;
                }
                const auto found = s.spins.find(key);
                if (found != s.spins.end())
                {
                    // It hit here after crossing, without the spin: the
                    // newer rebound's stays
                    ++s.counters.missed;
                    continue;
                }
                s.spins[key] = Spin{omegas[proci][i], times[proci][i]};
            }
        }
    }

    if (writeTime)
    {
        writeSpins(cloud, origProc, origId);
    }
}


void Foam::stochasticReboundCore::info(Ostream& os, subModelBase& model)
{
    State& s = *state_;
    const Counters& c = s.counters;

    // Totals: the values stored at the last write plus this run's since then
    auto total = [&model](const word& name, label now)
    {
        return model.getModelProperty<label>(name)
            + returnReduce(now, sumOp<label>());
    };
    auto totalScalar = [&model](const word& name, scalar now)
    {
        return model.getModelProperty<scalar>(name)
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
    const label nRemembered = total("nRememberedSpin", c.remembered);
    const label nMissed = total("nMissedSpin", c.missed);
    const scalar mTrapped = totalScalar("massTrapped", c.trappedMass);
    const scalar mFailed = totalScalar("massFailed", c.failedMass);
    const scalar directSeconds =
        totalScalar("directModelSeconds", c.directSeconds);
    const scalar workNormal = totalScalar("workNormal", c.workNormal);
    const scalar workTangential =
        totalScalar("workTangential", c.workTangential);
    const label nNoWork = total("nNoWork", c.noWork);
    label nSpin = model.getModelProperty<label>("nSpinSamples");
    scalar spinSum = model.getModelProperty<scalar>("spinRatioSum");
    scalar spinMax = model.getModelProperty<scalar>("spinRatioMax");

    // The trapped policy of the rules that draw: one, or per patch
    bool stuck = false, removed = false;
    for (const Rule& rule : *rules_)
    {
        if (rule.type == ruleDrawn && rule.table)
        {
            (rule.removeTrapped ? removed : stuck) = true;
        }
    }
    const char* policy =
        stuck && removed ? "stuck or removed (per patch)"
      : removed ? "removed" : "stuck";
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
        << "      - outside the table's grid    = " << nOutside << nl
        << "      - work on the walls (normal, tangential) = " << workNormal
        << ", " << workTangential << " J (" << nNoWork << " hits without"
        << " it: a table of format 4.0)" << nl;

    if (ownSpin_ || remembers())
    {
        nSpin += returnReduce(c.spinSamples, sumOp<label>());
        spinSum += returnReduce(c.spinRatioSum, sumOp<scalar>());
        spinMax = max(spinMax, returnReduce(c.spinRatioMax, maxOp<scalar>()));
        os  << "      - incoming spin |Omega|a/|V|  = mean "
            << (nSpin > 0 ? spinSum/nSpin : 0) << ", max " << spinMax
            << " (the table answers up to " << RBS_SPIN_TOLERANCE
            << " under auto)" << nl;
    }
    if (!ownSpin_)
    {
        os  << "      - spin memory (spinRelaxation) = "
            << describeMemory().c_str() << nl;
    }
    if (remembers())
    {
        os  << "      - hits with a remembered spin = " << nRemembered
            << " (held for "
            << returnReduce(label(s.spins.size()), sumOp<label>())
            << " parcels; " << nMissed << " missed it: crossed to another"
            << " rank and hit there in the same time step)" << nl;
    }

    // Per patch: this run's counts over the ranks, plus those stored at the
    // last write
    labelList counts(s.patchCounts);
    Pstream::listCombineGather(counts, plusEqOp<label>());
    Pstream::listCombineScatter(counts);
    scalarList work(s.patchWork);
    Pstream::listCombineGather(work, plusEqOp<scalar>());
    Pstream::listCombineScatter(work);
    List<labelList> patchTotals(patchRule_.size());
    List<scalarList> patchWorkTotals(patchRule_.size());
    size_t width = 5;
    forAll(patchRule_, patchi)
    {
        if (patchRule_[patchi] < 0)
        {
            continue;
        }
        labelList& total = patchTotals[patchi];
        total.setSize(nPatchCounts, Zero);
        model.getModelProperty
        (
            word("patchCounts_" + patchNames_[patchi]),
            total
        );
        if (total.size() != nPatchCounts)
        {
            total.setSize(nPatchCounts, Zero);
        }
        for (label k = 0; k < nPatchCounts; ++k)
        {
            total[k] += counts[nPatchCounts*patchi + k];
        }
        scalarList& sums = patchWorkTotals[patchi];
        sums.setSize(2, Zero);
        model.getModelProperty
        (
            word("patchWork_" + patchNames_[patchi]),
            sums
        );
        if (sums.size() != 2)
        {
            sums.setSize(2, Zero);
        }
        sums[0] += work[2*patchi];
        sums[1] += work[2*patchi + 1];
        width = std::max(width, patchNames_[patchi].size());
    }

    // The columns of PatchCount, then what the patch does
    static const char* const columns[nPatchCounts] =
    {
        "hits", "rebounded", "stuck", "removed", "escaped", "invalid",
        "trapped", "failed", "table", "direct", "|V|<grid", "|V|>grid",
        "alpha1-out", "out-of-law", "hit-again", "at-cap", "no-work"
    };
    char cell[256];
    std::string line("      ");
    std::snprintf(cell, sizeof(cell), "%-*s", int(width), "patch");
    line += cell;
    for (const char* name : columns)
    {
        std::snprintf(cell, sizeof(cell), " %10s", name);
        line += cell;
    }
    for (const char* name : {"roughness", "Wn/hit", "Wt/hit"})
    {
        std::snprintf(cell, sizeof(cell), " %10s", name);
        line += cell;
    }
    os  << "    Per patch (hits; their fate; the path; hits outside the"
        << " table's grid: |V| below, |V| above, alpha1 outside; outside"
        << " the wall law's speeds; hits that hit the wall again, and those"
        << " that reached " << RBS_MAX_WALL_HITS << " wall hits; hits"
        << " without wall work; the wall's roughness, deg; the mean work on"
        << " the wall per hit with work, normal and tangential, J/kg)" << nl
        << line.c_str() << "  interaction" << nl;
    forAll(patchRule_, patchi)
    {
        if (patchRule_[patchi] < 0)
        {
            continue;
        }
        std::snprintf
        (
            cell, sizeof(cell), "      %-*s", int(width),
            patchNames_[patchi].c_str()
        );
        line = cell;
        for (const label n : patchTotals[patchi])
        {
            std::snprintf(cell, sizeof(cell), " %10ld", long(n));
            line += cell;
        }
        const Rule& rule = (*rules_)[patchRule_[patchi]];
        if (rule.type == ruleDrawn)
        {
            std::snprintf(cell, sizeof(cell), " %10g", rule.roughnessDeg);
        }
        else
        {
            std::snprintf(cell, sizeof(cell), " %10s", "-");
        }
        line += cell;
        // Over the drawn hits whose work addWork added
        const labelList& n = patchTotals[patchi];
        const label nWork = n[pcHits] - n[pcInvalid] - n[pcNoWork];
        for (const scalar sum : patchWorkTotals[patchi])
        {
            if (rule.type == ruleDrawn && nWork > 0)
            {
                std::snprintf(cell, sizeof(cell), " %10.6g", sum/nWork);
            }
            else
            {
                std::snprintf(cell, sizeof(cell), " %10s", "-");
            }
            line += cell;
        }
        os  << line.c_str() << "  " << describe(rule, false).c_str() << nl;
    }

    if (s.hits.is_open())
    {
        s.hits.flush();
        s.work.flush();
    }

    if (model.writeTime())
    {
        model.setModelProperty("nHits", nHits);
        model.setModelProperty("nTablePath", nTable);
        model.setModelProperty("nDirectPath", nDirect);
        model.setModelProperty("nRebounded", nRebounded);
        model.setModelProperty("nTrapped", nTrapped);
        model.setModelProperty("nFailed", nFailed);
        model.setModelProperty("nInvalid", nInvalid);
        model.setModelProperty("nOutsideGrid", nOutside);
        model.setModelProperty("nRememberedSpin", nRemembered);
        model.setModelProperty("nMissedSpin", nMissed);
        model.setModelProperty("massTrapped", mTrapped);
        model.setModelProperty("massFailed", mFailed);
        model.setModelProperty("directModelSeconds", directSeconds);
        model.setModelProperty("nSpinSamples", nSpin);
        model.setModelProperty("spinRatioSum", spinSum);
        model.setModelProperty("spinRatioMax", spinMax);
        model.setModelProperty("workNormal", workNormal);
        model.setModelProperty("workTangential", workTangential);
        model.setModelProperty("nNoWork", nNoWork);
        forAll(patchRule_, patchi)
        {
            if (patchRule_[patchi] >= 0)
            {
                model.setModelProperty
                (
                    word("patchCounts_" + patchNames_[patchi]),
                    patchTotals[patchi]
                );
                model.setModelProperty
                (
                    word("patchWork_" + patchNames_[patchi]),
                    patchWorkTotals[patchi]
                );
            }
        }
        s.counters = Counters();
        s.patchCounts = Zero;
        s.patchWork = Zero;
    }
}


// ************************************************************************* //
