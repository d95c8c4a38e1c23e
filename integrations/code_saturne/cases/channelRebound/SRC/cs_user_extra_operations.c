/*============================================================================
 * channelRebound: rebound-scatter's counts at the end of the run
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
#include "cs_prototypes.h"

#include "rbs_cs_rebound.h"

BEGIN_C_DECLS

void
cs_user_extra_operations_finalize(cs_domain_t  *domain)
{
  CS_UNUSED(domain);
  rbs_cs_finalize();
}

END_C_DECLS
