/*============================================================================
 * channelRebound: still air (laminar), 200 time steps of 20 us
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

#include "cs_domain.h"
#include "cs_log.h"
#include "cs_prototypes.h"
#include "cs_time_step.h"
#include "cs_turbulence_model.h"

BEGIN_C_DECLS

void
cs_user_model(void)
{
  /* the particles cross still air: no turbulence model */
  cs_get_glob_turb_model()->iturb = CS_TURB_NONE;
}

void
cs_user_parameters(cs_domain_t  *domain)
{
  /* particles at up to 300 m/s cross about two 3.3 mm cells per step */
  cs_get_glob_time_step_options()->idtvar = 0;
  domain->time_step->dt_ref = 2.e-5;
  domain->time_step->nt_max = 200;

  /* the fluid's iteration log every 100 steps (and the first ones): a logged
     step makes most of the run's global sums over the ranks, each waiting
     for the other rank to get a core. lagrangian.log keeps a row per step. */
  cs_glob_log_frequency = 100;
}

END_C_DECLS
