/*============================================================================
 * channelRebound: one-way coupled particle tracking, first-order in time;
 * the boundary statistics
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

#include "cs_lagr.h"
#include "cs_lagr_prototypes.h"
#include "cs_lagr_stat.h"

#include "rbs_cs_rebound.h"

BEGIN_C_DECLS

void
cs_user_lagr_model(void)
{
  cs_glob_lagr_time_scheme->iilagr = CS_LAGR_ONEWAY_COUPLING;
  cs_glob_lagr_time_scheme->isuila = 0;
  cs_glob_lagr_model->physical_model = 0;

  /* the air is at rest: steady statistics, summed from the first step to
     the last, among them rebound-scatter's work on the walls */
  cs_glob_lagr_time_scheme->isttio = 1;
  cs_glob_lagr_stat_options->idstnt = 1;
  cs_glob_lagr_stat_options->nstist = 1;
  rbs_cs_define_statistics();

  /* laminar air: no turbulent dispersion; one step per time step, so that
     each wall hit is met once */
  cs_glob_lagr_time_scheme->idistu = 0;
  cs_glob_lagr_time_scheme->t_order = 1;
}

END_C_DECLS
