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


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

template<class CloudType>
Foam::StochasticRebound<CloudType>::StochasticRebound
(
    const dictionary& dict,
    CloudType& cloud
)
:
    PatchInteractionModel<CloudType>(dict, cloud, typeName),
    core_
    (
        this->coeffDict(),
        cloud.mesh(),
        cloud,
        stochasticReboundDetail::hasSpin
        <
            typename CloudType::parcelType
        >::value,
        cloud.solution().steadyState()
    )
{
    if (core_.autoRelaxation())
    {
        // tau_r needs the gas viscosity: the field the cloud was given
        // (kinematic clouds: the solver's; thermo clouds: the gas thermo's)
        const scalar muMin = gMin(cloud.mu().primitiveField());
        if (!(muMin > 0))
        {
            FatalIOErrorInFunction(this->coeffDict())
                << "spinRelaxation auto needs the gas viscosity, but the"
                << " cloud's mu field is not > 0 everywhere (min " << muMin
                << "): give spinRelaxation as a time in s, or off"
                << exit(FatalIOError);
        }
    }
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

template<class CloudType>
bool Foam::StochasticRebound<CloudType>::correct
(
    typename CloudType::parcelType& p,
    const polyPatch& pp,
    bool& keepParticle
)
{
    const CloudType& cloud = this->owner();
    stochasticReboundCore::Parcel parcel;
    // OpenFOAM's normal at the hit point points out of the domain (into the
    // wall); the wall velocity includes a moving wall's tangential velocity
    cloud.patchData(p, pp, parcel.nw, parcel.Uwall);
    parcel.U = p.U();
    parcel.Omega = stochasticReboundDetail::angularVelocity(p, 0);
    parcel.d = p.d();
    parcel.rho = p.rho();
    parcel.mu = core_.autoRelaxation() ? cloud.mu()[p.cell()] : 0;
    parcel.mass = p.nParticle()*p.mass();
    parcel.face = pp.whichFace(p.face());
    parcel.origProc = p.origProc();
    parcel.origId = p.origId();
    // The hit's time: the parcel has tracked stepFraction of this step
    parcel.time =
        cloud.db().time().value()
      - (1 - p.stepFraction())*cloud.solution().trackTime();

    stochasticReboundCore::Outcome out;
    if (!core_.correct(pp, parcel, out))
    {
        return false;
    }
    switch (out.fate)
    {
        case stochasticReboundCore::fateRebound:
        {
            keepParticle = true;
            p.active(true);
            p.U() = out.U;
            stochasticReboundDetail::setAngularVelocity(p, out.Omega, 0);
            break;
        }
        case stochasticReboundCore::fateStopped:
        case stochasticReboundCore::fateRemoved:
        {
            keepParticle = out.fate == stochasticReboundCore::fateStopped;
            p.active(false);
            p.U() = Zero;
            stochasticReboundDetail::setAngularVelocity(p, vector(Zero), 0);
            break;
        }
        default:
        {
            keepParticle = true;
            break;
        }
    }
    return true;
}


template<class CloudType>
void Foam::StochasticRebound<CloudType>::info(Ostream& os)
{
    PatchInteractionModel<CloudType>::info(os);

    if (core_.remembers())
    {
        // The ids of the parcels on this rank, in the cloud's order
        const CloudType& cloud = this->owner();
        labelList origProc(cloud.size());
        labelList origId(cloud.size());
        label i = 0;
        for (const typename CloudType::parcelType& p : cloud)
        {
            origProc[i] = p.origProc();
            origId[i] = p.origId();
            ++i;
        }
        core_.endOfStep(cloud, origProc, origId, this->writeTime());
    }
    core_.info(os, *this);
}


// ************************************************************************* //
