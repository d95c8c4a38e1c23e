/*---------------------------------------------------------------------------*\
    stochasticRebound: a patch interaction model for OpenFOAM's Lagrangian
    clouds that draws the rebound of non-spherical particles from a
    rebound-scatter table through the rebound-scatter C runtime.

    Copyright (C) 2026 the rebound-scatter authors
-------------------------------------------------------------------------------
License
    This file is part of the rebound-scatter OpenFOAM adapter, which is
    derived from and links with OpenFOAM. It is free software: you can
    redistribute it and/or modify it under the terms of the GNU General
    Public License as published by the Free Software Foundation, either
    version 3 of the License, or (at your option) any later version. It is
    distributed WITHOUT ANY WARRANTY; see the GNU General Public License
    (integrations/openfoam/LICENSE) for more details.

Description
    Registers stochasticRebound for the heterogeneous reacting cloud
    (basicHeterogeneousReactingCloud: reactingHeterogenousParcelFoam).

\*---------------------------------------------------------------------------*/

#include "basicHeterogeneousReactingCloud.H"
#include "makeStochasticRebound.H"

// * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * * //

makeStochasticRebound(basicHeterogeneousReactingCloud, heterogeneous);


// ************************************************************************* //
