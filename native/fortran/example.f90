! example.f90: load a table and draw rebounds from Fortran.
!
!   rbs_example_fortran TABLE.h5
!
! Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
program rebound_example
  use, intrinsic :: iso_c_binding
  use rebound_scatter
  implicit none
  integer, parameter :: n_many = 1000
  type(c_ptr) :: table, mix, prism
  type(rbs_rng), target :: rng
  type(rbs_hit) :: hit
  type(rbs_options) :: direct
  type(rbs_result) :: result
  type(rbs_hits) :: hits
  type(rbs_results) :: results
  type(rbs_table_info) :: info
  type(rbs_grain) :: grain
  character(len=1024) :: path, message
  real(c_double), target :: u(RBS_U_PER_DRAW)
  real(c_double), target :: Vs(3, n_many), ns(3, n_many), a(n_many), Vs_out(3, n_many), Ws_out(3, n_many)
  integer(c_signed_char), target :: status(n_many)
  integer(c_int) :: code, st, i

  if (command_argument_count() < 1) then
    print '(a)', "usage: rbs_example_fortran TABLE.h5"
    stop 2
  end if
  call get_command_argument(1, path)
  code = rbs_open(path, table, message)
  if (code /= RBS_OK) then
    print '(a, i0, 3a)', "error ", code, " (", rbs_status_string(code), "): " // trim(message)
    stop 1
  end if
  mix = rbs_mix_new_equal(table)        ! a mix of the table's shapes, however many, equal weights
  if (.not. c_associated(mix)) stop 7
  call rbs_init(info)
  if (rbs_table_info_get(table, info) /= RBS_OK) stop 10
  print '(i0, a, f6.2, a, f6.2, a, a)', rbs_table_n_shapes(table), " shapes, equal weights; alpha1 grid ", &
      info%alpha1_min_deg, " to ", info%alpha1_max_deg, " deg; library ", rbs_version()
  call rbs_rng_seed(rng, 1_c_int64_t)

  ! one particle at a time, every hit answered (here no spin: the table answers); uniforms from rng
  call rbs_init(hit)
  call rbs_init(result)
  hit%V = [120.0_c_double, -80.0_c_double, 10.0_c_double]      ! m/s, into the wall
  hit%n = [0.0_c_double, 1.0_c_double, 0.0_c_double]           ! unit normal into the gas
  hit%a = 5e-5_c_double                                        ! m
  hit%rng = c_loc(rng)
  do i = 1, 3
    st = rbs_rebound(table, mix, hit, result=result)             ! no options: the defaults
    print '(a, i0, a, i0, a, 3f10.3, a, 3es12.3)', "status ", st, " path ", result%path, "  V+ =", result%V, &
        "  Omega+ =", result%Omega
  end do

  ! a spinning prism by the direct model (RBS_METHOD_DIRECT: the impulse model simulated; Omega in rad/s)
  prism = rbs_mix_new_from_shape(table, "prism", message)
  if (.not. c_associated(prism)) then
    print '(a)', trim(message)
    stop 11
  end if
  call rbs_init(direct)
  direct%method = RBS_METHOD_DIRECT
  hit%Omega = [0.0_c_double, 0.0_c_double, 2e5_c_double]
  call rbs_rng_fill(rng, u, int(RBS_U_PER_DRAW, c_size_t))
  hit%u = c_loc(u)                                             ! these uniforms, not rng's
  st = rbs_rebound(table, prism, hit, direct, result)
  print '(a, i0, a, i0, a, 3f10.3, a, 3es12.3)', "direct: status ", st, ", collisions ", result%n_collisions, &
      "  V+ =", result%V, "  Omega+ =", result%Omega
  if (st /= RBS_OK .or. result%V(2) <= 0.0_c_double) stop 5     ! this one rebounds, leaving the wall
  call rbs_mix_free(prism)
  hit%u = c_null_ptr

  ! a spinning particle, |Omega-| a/|V-| = 0.3: the direct model answers under RBS_METHOD_AUTO
  hit%Omega = [0.0_c_double, 0.3_c_double * norm2(hit%V) / hit%a, 0.0_c_double]      ! rad/s
  st = rbs_rebound(table, mix, hit, result=result)
  print '(a, i0, a, i0, a, 3f10.3)', "spinning: path ", result%path, ", status ", st, "  V+ =", result%V
  if (rbs_rebound_path(table, hit) /= RBS_PATH_DIRECT .or. result%path /= RBS_PATH_DIRECT) stop 6

  ! a particle of its own grain: its key from (seed, rank, id); every hit of it is the same grain, spinning or not
  hit%grain_key = rbs_grain_key(1_c_int64_t, 0_c_int64_t, 42_c_int64_t)
  call rbs_init(grain)
  if (rbs_grain_info(table, mix, hit%grain_key, grain) /= RBS_OK) stop 8
  print '(a, i0, 3a, 3f8.4)', "grain: key ", hit%grain_key, ", shape ", &
      rbs_c_string(rbs_table_shape_name(table, grain%shape)), ", b/a c/b hand", grain%ratio_ba, grain%ratio_cb, &
      grain%hand
  do i = 1, 2
    st = rbs_rebound(table, mix, hit, result=result)
    print '(a, i0, a, i0, a, 3f10.3)', "grain hit: status ", st, ", shape ", result%shape, "  V+ =", result%V
    if (st == RBS_INVALID .or. result%shape /= grain%shape) stop 9
  end do

  ! many particles in one call (the faster path), uniforms from rng
  do i = 1, n_many
    Vs(:, i) = [120.0_c_double, -80.0_c_double, 10.0_c_double]
    ns(:, i) = [0.0_c_double, 1.0_c_double, 0.0_c_double]
  end do
  a = 5e-5_c_double
  call rbs_init(hits)
  hits%count = n_many
  hits%V = c_loc(Vs)
  hits%n = c_loc(ns)
  hits%a = c_loc(a)
  hits%rng = c_loc(rng)
  call rbs_init(results)
  results%V = c_loc(Vs_out)
  results%Omega = c_loc(Ws_out)
  results%status = c_loc(status)
  if (rbs_draw_many(table, mix, hits, results=results) /= RBS_OK) stop 12
  print '(a, i0, a, i0, a, i0, a)', "many: ", n_many, " particles, ", count_status(RBS_OK), &
      " rebounded, ", count_status(RBS_TRAPPED), " trapped"
  if (count_status(RBS_OK) + count_status(RBS_TRAPPED) /= n_many) stop 3
  if (any(status == RBS_OK .and. Vs_out(2, :) <= 0.0_c_double)) stop 4   ! rebounds leave the wall
  call rbs_mix_free(mix)
  call rbs_table_close(table)
  print '(a)', "ok"

contains

  integer function count_status(code)
    integer(c_int), intent(in) :: code
    count_status = int(count(status == code))
  end function count_status
end program rebound_example
