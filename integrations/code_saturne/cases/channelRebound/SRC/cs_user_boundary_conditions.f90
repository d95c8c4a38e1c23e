!===============================================================================
! channelRebound: the air's boundary conditions, walls and a free outlet at the
! inlet (code_saturne 6.0 reads them from this Fortran subroutine when the case
! has no setup.xml)
!
! Copyright (C) 2026 the rebound-scatter authors
!
! This program is free software; you can redistribute it and/or modify it
! under the terms of the GNU General Public License as published by the Free
! Software Foundation; either version 2 of the License, or (at your option)
! any later version.
!
! This program is distributed in the hope that it will be useful, but WITHOUT
! ANY WARRANTY; without even the implied warranty of MERCHANTABILITY or
! FITNESS FOR A PARTICULAR PURPOSE.  See the GNU General Public License for
! more details.
!
! You should have received a copy of the GNU General Public License along with
! this program (integrations/code_saturne/LICENSE); if not, write to the Free
! Software Foundation, Inc., 51 Franklin Street, Fifth Floor, Boston, MA
! 02110-1301, USA.
!===============================================================================

subroutine cs_f_user_boundary_conditions &
 ( nvar   , nscal  ,                                              &
   icodcl , itrifb , itypfb , izfppp ,                            &
   dt     ,                                                       &
   rcodcl )

use paramx
use mesh

implicit none

integer          nvar   , nscal
integer          icodcl(nfabor,nvar)
integer          itrifb(nfabor), itypfb(nfabor)
integer          izfppp(nfabor)
double precision dt(ncelet)
double precision rcodcl(nfabor,nvar,3)

integer          ilelt, nlelt
integer, allocatable, dimension(:) :: lstelt

allocate(lstelt(nfabor))

! the mesh's groups (make_mesh.py): 1 inlet, 2 target, 3 walls; the air stays
! at rest, the open end fixes its pressure
call getfbr('1', nlelt, lstelt)
do ilelt = 1, nlelt
  itypfb(lstelt(ilelt)) = isolib
enddo

call getfbr('2 or 3', nlelt, lstelt)
do ilelt = 1, nlelt
  itypfb(lstelt(ilelt)) = iparoi
enddo

deallocate(lstelt)

return
end subroutine cs_f_user_boundary_conditions
