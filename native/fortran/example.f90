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
  type(c_ptr) :: table
  type(rbs_mix), pointer :: mix
  type(rbs_rng) :: rng
  character(len=1024) :: path, message
  real(c_double) :: V(3), n(3), u(RBS_U_PER_DRAW), V_out(3), Omega_out(3), Omega(3), ud(RBS_U_PER_REBOUND)
  real(c_double) :: Vs(3, n_many), ns(3, n_many), a(n_many), Vs_out(3, n_many), Ws_out(3, n_many)
  integer(c_signed_char) :: status(n_many)
  integer(c_int) :: code, st, i, answered_by
  integer(c_int64_t) :: key
  type(rbs_grain) :: grain

  if (command_argument_count() < 1) then
    print '(a)', "usage: rbs_example_fortran TABLE.h5"
    stop 2
  end if
  call get_command_argument(1, path)
  code = rbs_open(path, table, message)
  if (code /= RBS_OK) then
    print '(a, i0, 3a)', "error ", code, " (", rbs_error_string(code), "): " // trim(message)
    stop 1
  end if
  mix => rbs_mix_new_equal(table)       ! a mix sized by the table: any number of shapes
  if (.not. associated(mix)) stop 7
  print '(i0, a)', rbs_table_n_shapes(table), " shapes, equal weights"
  call rbs_rng_seed(rng, 1_c_int64_t)

  ! one particle at a time, every hit answered (here no spin: the table answers)
  V = [120.0_c_double, -80.0_c_double, 10.0_c_double]      ! m/s, into the wall
  n = [0.0_c_double, 1.0_c_double, 0.0_c_double]           ! unit normal into the gas
  Omega = 0.0_c_double                                     ! rad/s
  do i = 1, 3
    call rbs_rng_fill(rng, u, int(RBS_U_PER_DRAW, c_size_t))
    st = rbs_rebound(table, mix, V, Omega, n, 5e-5_c_double, u, RBS_AUTO, RBS_SCALED, V_out, Omega_out)
    print '(a, i0, a, 3f10.3, a, 3es12.3)', "status ", st, "  V+ =", V_out, "  Omega+ =", Omega_out
  end do

  ! a spinning particle by the direct path alone (the impulse model simulated; Omega in rad/s)
  Omega = [0.0_c_double, 0.0_c_double, 2e5_c_double]
  call rbs_rng_fill(rng, ud, int(RBS_U_PER_REBOUND, c_size_t))
  st = rbs_direct_rebound(table, RBS_PRISM, V, Omega, n, 5e-5_c_double, ud, V_out, Omega_out)
  print '(a, i0, a, 3f10.3, a, 3es12.3)', "direct: status ", st, "  V+ =", V_out, "  Omega+ =", Omega_out
  if (st /= RBS_REBOUNDED .or. V_out(2) <= 0.0_c_double) stop 5   ! this one rebounds, leaving the wall

  ! a spinning particle, |Omega-| a/|V-| = 0.3: the direct model answers under RBS_AUTO
  Omega = [0.0_c_double, 0.3_c_double * norm2(V) / 5e-5_c_double, 0.0_c_double]     ! rad/s
  answered_by = rbs_rebound_path(table, V, Omega, n, 5e-5_c_double, RBS_AUTO)
  st = rbs_rebound_rng(table, mix, V, Omega, n, 5e-5_c_double, rng, RBS_AUTO, RBS_SCALED, V_out, Omega_out)
  print '(a, i0, a, i0, a, 3f10.3)', "spinning: path ", answered_by, ", status ", st, "  V+ =", V_out
  if (answered_by /= RBS_PATH_DIRECT) stop 6

  ! a particle of its own grain: its key from (seed, rank, id); every hit of it is the same grain, spinning or not
  key = rbs_grain_key(1_c_int64_t, 0_c_int64_t, 42_c_int64_t)
  if (rbs_grain_info(table, mix, key, grain) /= RBS_OK) stop 8
  print '(a, i0, a, i0, a, 3f8.4)', "grain: key ", key, ", shape ", grain%shape, ", b/a c/b hand", &
      grain%ratio_ba, grain%ratio_cb, grain%hand
  do i = 1, 2
    st = rbs_rebound_grain_rng(table, mix, key, V, Omega, n, 5e-5_c_double, rng, RBS_AUTO, RBS_SCALED, V_out, &
                               Omega_out)
    print '(a, i0, a, 3f10.3)', "grain hit: status ", st, "  V+ =", V_out
    if (st == RBS_INVALID) stop 9
  end do

  ! many particles in one call (the faster path)
  do i = 1, n_many
    Vs(:, i) = V
    ns(:, i) = n
  end do
  a = 5e-5_c_double
  call rbs_table_rebound_many_rng(table, mix, int(n_many, c_size_t), Vs, ns, a, rng, RBS_SCALED, Vs_out, Ws_out, status)
  print '(a, i0, a, i0, a, i0, a)', "many: ", n_many, " particles, ", count_status(RBS_REBOUNDED), &
      " rebounded, ", count_status(RBS_TRAPPED), " trapped"
  if (count_status(RBS_REBOUNDED) + count_status(RBS_TRAPPED) /= n_many) stop 3
  if (any(status == RBS_REBOUNDED .and. Vs_out(2, :) <= 0.0_c_double)) stop 4   ! rebounds leave the wall
  call rbs_mix_free(mix)
  call rbs_table_close(table)
  print '(a)', "ok"

contains

  integer function count_status(code)
    integer(c_int), intent(in) :: code
    count_status = int(count(status == code))
  end function count_status
end program rebound_example
