#ifndef RBS_CS_REBOUND_H
#define RBS_CS_REBOUND_H

/*============================================================================
 * rebound-scatter for code_saturne 6.0's Lagrangian module: the wall
 * rebounds of particles on boundary zones of type CS_LAGR_BC_USER drawn by
 * the rebound-scatter C runtime (rbs_cs_rebound.c).
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

/*
 * Use: put rbs_cs_rebound.c and this header in the case's SRC folder, give
 * the walls the zone type CS_LAGR_BC_USER in cs_user_lagr_boundary_conditions
 * and call rbs_cs_initialize() there after the zone types, call
 * rbs_cs_finalize() from cs_user_extra_operations_finalize (and, for the
 * boundary statistics of the work on the walls, rbs_cs_define_statistics()
 * from cs_user_lagr_model), and link the C
 * runtime (code_saturne compile --cflags=-I<prefix>/include
 *  --libs="-L<prefix>/lib -lrebound_scatter -Wl,-rpath,<prefix>/lib").
 * The settings, global and per boundary zone, are read from a key = value
 * file with [zone NAME] sections (docs/code_saturne.md).
 */

#ifdef __cplusplus
extern "C" {
#endif

/* Read the settings (the file named by $RBS_CS_SETUP, else
 * rebound_scatter.conf in the run folder), open the tables, check the zones
 * the settings name against the Lagrangian zone types given so far (so call
 * it after them), seed this rank's stream and open its hits file. Called on
 * every rank; only the first call does anything. A bad setting stops the run
 * with one message (bft_error) naming the file, the section, the key, the
 * value and what is allowed. */
void rbs_cs_initialize(void);

/* Define the adapter's boundary statistics, per boundary face over the
 * hits a table or the direct model answered with work on the wall (a table
 * of format 4.0 gives none): the work on the wall,
 * rbs_wall_work_normal and rbs_wall_work_tangential (statistical weight x
 * particle mass x W_n, W_t, J), the mass that hit, rbs_wall_hit_mass
 * (weight x mass, kg), and the hits, rbs_wall_hits (weight). Lagrangian
 * statistics of 6.0 (cs_lagr_stat_mesh_define): postprocessed on the
 * boundary and logged; per time step, or summed from the step nstist with
 * steady statistics (isttio = 1). Call it from cs_user_lagr_model; optional
 * (the summary's work does not need it). */
void rbs_cs_define_statistics(void);

/* The counts and the work on the walls summed over the ranks, in total and
 * per zone, written to the solver's log; the hits files closed and the
 * tables released. Collective: call it on every rank. */
void rbs_cs_finalize(void);

#ifdef __cplusplus
}
#endif

#endif /* RBS_CS_REBOUND_H */
