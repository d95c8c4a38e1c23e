/*============================================================================
 * channelRebound: the particles' boundary zones and their injection
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

#include <stdlib.h>
#include <string.h>

#include "bft_error.h"

#include "cs_boundary_zone.h"
#include "cs_time_step.h"

#include "cs_lagr.h"
#include "cs_lagr_prototypes.h"

#include "rbs_cs_rebound.h"

BEGIN_C_DECLS

/* Injection: 50 particles per time step for the first 50 steps (1 ms) */
#define N_PER_STEP 50
#define N_STEPS_INJECTING 50

void
cs_user_lagr_boundary_conditions(const int  bc_type[])
{
  CS_UNUSED(bc_type);
  cs_lagr_zone_data_t *lagr_bcs = cs_lagr_get_boundary_conditions();

  /* The walls' rebound: rebound-scatter's (CS_LAGR_BC_USER) or, with
     RBS_CS_WALLS=specular, the solver's own (CS_LAGR_REBOUND) */
  const char *walls = getenv("RBS_CS_WALLS");
  int wall_type = CS_LAGR_BC_USER;
  if (walls != NULL && strcmp(walls, "specular") == 0)
    wall_type = CS_LAGR_REBOUND;
  else if (walls != NULL && walls[0] != '\0'
           && strcmp(walls, "rebound-scatter") != 0)
    bft_error(__FILE__, __LINE__, 0,
              "RBS_CS_WALLS must be rebound-scatter or specular, not \"%s\"",
              walls);

  /* Every zone but the inlet is a wall (zone 0 is the zone of the faces no
     zone selects: none here) */
  const cs_zone_t *inlet = cs_boundary_zone_by_name("inlet");
  lagr_bcs->zone_type[inlet->id] = CS_LAGR_INLET;
  for (int z_id = 1; z_id < cs_boundary_zone_n_zones(); z_id++)
    if (z_id != inlet->id)
      lagr_bcs->zone_type[z_id] = wall_type;

  /* after the zone types: it checks those its settings name */
  if (wall_type == CS_LAGR_BC_USER)
    rbs_cs_initialize();

  /* Sand (2650 kg/m3); speed, direction and diameter set per particle in
     cs_user_lagr_in */
  cs_lagr_injection_set_t *zis
    = cs_lagr_get_injection_set(lagr_bcs, inlet->id, 0);
  zis->n_inject = (cs_glob_time_step->nt_cur <= N_STEPS_INJECTING)
    ? N_PER_STEP : 0;
  zis->injection_frequency = 1;
  zis->velocity_profile = 1;
  zis->velocity[0] = 150.;
  zis->velocity[1] = 0.;
  zis->velocity[2] = 0.;
  zis->stat_weight = 1.;
  zis->flow_rate = 0.;
  zis->diameter = 2.e-4;
  zis->diameter_variance = 0.;
  zis->density = 2650.;
  zis->fouling_index = 100.;
}

END_C_DECLS
