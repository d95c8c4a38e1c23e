/*============================================================================
 * channelRebound: each injected particle's speed, direction and size
 *
 * Copyright (C) 2026 the rebound-scatter authors
 *
 * This program is free software; you can redistribute it and/or modify it
 * under the terms of the GNU General Public License as published by the Free
 * Software Foundation; either version 2 of the License, or (at your option)
 * any later version.
 *
 * This program is distributed in the hope that it will be useful, but WITHOUT
 * ANY WARRANTY; without even the implied warranty of MERCHANTABILITY or
 * FITNESS FOR A PARTICULAR PURPOSE.  See the GNU General Public License for
 * more details.
 *
 * You should have received a copy of the GNU General Public License along with
 * this program (integrations/code_saturne/LICENSE); if not, write to the Free
 * Software Foundation, Inc., 51 Franklin Street, Fifth Floor, Boston, MA
 * 02110-1301, USA.
 *============================================================================*/

#include "cs_defs.h"

#include <math.h>

#include "cs_math.h"
#include "cs_random.h"

#include "cs_lagr.h"
#include "cs_lagr_particle.h"
#include "cs_lagr_prototypes.h"

BEGIN_C_DECLS

/* |V| uniform in 50-300 m/s, directions uniform over the 40 degree cone
   around +x, diameters uniform in 100-300 um: the grains reach the side
   walls at up to 40 degrees and the target at 50 degrees and more */
#define SPEED_LO 50.
#define SPEED_HI 300.
#define CONE_DEG 40.
#define D_LO 1.e-4
#define D_HI 3.e-4

void
cs_user_lagr_in(cs_lagr_particle_set_t         *particles,
                const cs_lagr_injection_set_t  *zis,
                const cs_lnum_t                 particle_range[2],
                const cs_lnum_t                 particle_face_id[],
                const cs_real_t                 visc_length[])
{
  CS_UNUSED(particle_face_id);
  CS_UNUSED(visc_length);
  const double cos_max = cos(CONE_DEG*cs_math_pi/180.);

  for (cs_lnum_t p = particle_range[0]; p < particle_range[1]; p++) {
    cs_real_t u[4];
    cs_random_uniform(4, u);
    const double speed = SPEED_LO + (SPEED_HI - SPEED_LO)*u[0];
    const double c = 1. - (1. - cos_max)*u[1];
    const double s = sqrt(1. - c*c), phi = 2.*cs_math_pi*u[2];
    const double d = D_LO + (D_HI - D_LO)*u[3];
    cs_real_t *v = cs_lagr_particles_attr(particles, p, CS_LAGR_VELOCITY);
    v[0] = speed*c;
    v[1] = speed*s*cos(phi);
    v[2] = speed*s*sin(phi);
    cs_lagr_particles_set_real(particles, p, CS_LAGR_DIAMETER, d);
    cs_lagr_particles_set_real(particles, p, CS_LAGR_MASS,
                               zis->density*cs_math_pi*d*d*d/6.);
  }
}

END_C_DECLS
