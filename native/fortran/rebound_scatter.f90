! rebound_scatter.f90: Fortran interfaces (iso_c_binding) to the native runtime of rebound-scatter.
!
! The C functions of rebound_scatter.h, called directly; units and frames as there (docs/native.md):
! V and V_out in m/s, Omega_out in rad/s, n a unit normal into the gas, a the half-size in m.
! Arrays of many particles are V(3, count): Fortran's column-major (3, count) is C's row-major (count, 3).
! Strings passed to C end with c_null_char: rbs_open does that for you.
!
! Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
module rebound_scatter
  use, intrinsic :: iso_c_binding
  implicit none
  private :: c_strlen

  integer(c_int), parameter :: RBS_U_PER_DRAW = 13, RBS_MAX_SHAPES = 4, RBS_LOCAL_SIZE = 6, RBS_BLOCK = 32
  integer(c_int), parameter :: RBS_REBOUNDED = 0, RBS_TRAPPED = 1, RBS_FAILED = 2, RBS_INVALID = -1
  integer(c_int), parameter :: RBS_U_PER_REBOUND = 7
  integer(c_int), parameter :: RBS_ELLIPSOID = 0, RBS_PRISM = 1, RBS_CUT_PRISM = 2, RBS_TETRAHEDRON = 3
  integer(c_int), parameter :: RBS_OK = 0, RBS_ERR_IO = 1, RBS_ERR_FORMAT = 2, RBS_ERR_VERSION = 3, &
                               RBS_ERR_ARGUMENT = 4, RBS_ERR_MEMORY = 5
  integer(c_int), parameter :: RBS_SCALED = 0, RBS_STOCHASTIC = 1
  ! methods of rbs_rebound and the paths of rbs_rebound_path
  integer(c_int), parameter :: RBS_AUTO = 0, RBS_TABLE = 1, RBS_DIRECT = 2
  integer(c_int), parameter :: RBS_PATH_TABLE = 0, RBS_PATH_DIRECT = 1
  real(c_double), parameter :: RBS_SPIN_TOLERANCE = 0.001_c_double

  ! cumulative shape weights in the table's shape order (rbs_mix). A mix of any table: a pointer from
  ! rbs_mix_new_equal or rbs_mix_new_from_shape (freed by rbs_mix_free); a variable of this type holds a mix of a
  ! table of at most RBS_MAX_SHAPES shapes (rbs_mix_equal, rbs_mix_from_shape). The draws take either.
  type, bind(c) :: rbs_mix
    integer(c_int) :: n_shapes
    real(c_double) :: cdf(RBS_MAX_SHAPES)
  end type rbs_mix

  ! one xoshiro256+ state (rbs_rng): one per thread / MPI rank
  type, bind(c) :: rbs_rng
    integer(c_int64_t) :: s(4)
  end type rbs_rng

  ! one grain of a table's mix (rbs_grain, rbs_grain_info): its table shape index (0-based), its direct-model
  ! shape (-1: none), the b/a, c/b and hand the direct path gives it (NaN where the key does not draw them)
  type, bind(c) :: rbs_grain
    integer(c_int) :: shape, direct_shape
    real(c_double) :: ratio_ba, ratio_cb, hand
  end type rbs_grain

  interface
    integer(c_int) function rbs_table_open(path, table, message, message_size) bind(c, name="rbs_table_open")
      import :: c_int, c_char, c_ptr, c_size_t
      character(kind=c_char), dimension(*), intent(in) :: path
      type(c_ptr), intent(out) :: table
      character(kind=c_char), dimension(*), intent(inout) :: message
      integer(c_size_t), value :: message_size
    end function rbs_table_open

    subroutine rbs_table_close(table) bind(c, name="rbs_table_close")
      import :: c_ptr
      type(c_ptr), value :: table
    end subroutine rbs_table_close

    integer(c_int) function rbs_table_n_shapes(table) bind(c, name="rbs_table_n_shapes")
      import :: c_int, c_ptr
      type(c_ptr), value :: table
    end function rbs_table_n_shapes

    subroutine rbs_table_alpha1_range(table, lo_deg, hi_deg) bind(c, name="rbs_table_alpha1_range")
      import :: c_ptr, c_double
      type(c_ptr), value :: table
      real(c_double), intent(out) :: lo_deg, hi_deg
    end subroutine rbs_table_alpha1_range

    subroutine rbs_table_speed_range(table, lo_m_s, hi_m_s) bind(c, name="rbs_table_speed_range")
      import :: c_ptr, c_double
      type(c_ptr), value :: table
      real(c_double), intent(out) :: lo_m_s, hi_m_s
    end subroutine rbs_table_speed_range

    integer(c_int) function rbs_mix_equal(table, mix) bind(c, name="rbs_mix_equal")
      import :: c_int, c_ptr, rbs_mix
      type(c_ptr), value :: table
      type(rbs_mix), intent(out) :: mix
    end function rbs_mix_equal

    integer(c_int) function rbs_mix_from_shape_c(table, name, mix, message, message_size) &
        bind(c, name="rbs_mix_from_shape")
      import :: c_int, c_ptr, c_char, c_size_t, rbs_mix
      type(c_ptr), value :: table
      character(kind=c_char), dimension(*), intent(in) :: name
      type(rbs_mix), intent(out) :: mix
      character(kind=c_char), dimension(*), intent(inout) :: message
      integer(c_size_t), value :: message_size
    end function rbs_mix_from_shape_c

    type(c_ptr) function rbs_mix_new_equal_c(table) bind(c, name="rbs_mix_new_equal")
      import :: c_ptr
      type(c_ptr), value :: table
    end function rbs_mix_new_equal_c

    type(c_ptr) function rbs_mix_new_from_shape_c(table, name, message, message_size) &
        bind(c, name="rbs_mix_new_from_shape")
      import :: c_ptr, c_char, c_size_t
      type(c_ptr), value :: table
      character(kind=c_char), dimension(*), intent(in) :: name
      character(kind=c_char), dimension(*), intent(inout) :: message
      integer(c_size_t), value :: message_size
    end function rbs_mix_new_from_shape_c

    subroutine rbs_mix_free_c(mix) bind(c, name="rbs_mix_free")
      import :: c_ptr
      type(c_ptr), value :: mix
    end subroutine rbs_mix_free_c

    ! Every wall hit: call this first. The table where its law is valid, the direct model elsewhere; Omega the
    ! incident angular velocity in rad/s; method RBS_AUTO, RBS_TABLE or RBS_DIRECT; u RBS_U_PER_DRAW uniforms
    integer(c_int) function rbs_rebound(table, mix, V, Omega, n, a, u, method, interpolation, V_out, &
        Omega_out) bind(c, name="rbs_rebound")
      import :: c_int, c_ptr, c_double, rbs_mix, RBS_U_PER_DRAW
      type(c_ptr), value :: table
      type(rbs_mix), intent(in) :: mix
      real(c_double), intent(in) :: V(3), Omega(3), n(3)
      real(c_double), value :: a
      real(c_double), intent(in) :: u(RBS_U_PER_DRAW)
      integer(c_int), value :: method, interpolation
      real(c_double), intent(out) :: V_out(3), Omega_out(3)
    end function rbs_rebound

    ! rbs_rebound with its uniforms drawn from rng
    integer(c_int) function rbs_rebound_rng(table, mix, V, Omega, n, a, rng, method, interpolation, V_out, &
        Omega_out) bind(c, name="rbs_rebound_rng")
      import :: c_int, c_ptr, c_double, rbs_mix, rbs_rng
      type(c_ptr), value :: table
      type(rbs_mix), intent(in) :: mix
      real(c_double), intent(in) :: V(3), Omega(3), n(3)
      real(c_double), value :: a
      type(rbs_rng), intent(inout) :: rng
      integer(c_int), value :: method, interpolation
      real(c_double), intent(out) :: V_out(3), Omega_out(3)
    end function rbs_rebound_rng

    integer(c_int) function rbs_rebound_path(table, V, Omega, n, a, method) bind(c, name="rbs_rebound_path")
      import :: c_int, c_ptr, c_double
      type(c_ptr), value :: table
      real(c_double), intent(in) :: V(3), Omega(3), n(3)
      real(c_double), value :: a
      integer(c_int), value :: method
    end function rbs_rebound_path

    ! the table path alone
    integer(c_int) function rbs_table_rebound(table, mix, V, n, a, u, interpolation, V_out, Omega_out) &
        bind(c, name="rbs_table_rebound")
      import :: c_int, c_ptr, c_double, rbs_mix, RBS_U_PER_DRAW
      type(c_ptr), value :: table
      type(rbs_mix), intent(in) :: mix
      real(c_double), intent(in) :: V(3), n(3)
      real(c_double), value :: a
      real(c_double), intent(in) :: u(RBS_U_PER_DRAW)
      integer(c_int), value :: interpolation
      real(c_double), intent(out) :: V_out(3), Omega_out(3)
    end function rbs_table_rebound

    subroutine rbs_table_rebound_many(table, mix, count, V, n, a, u, interpolation, V_out, Omega_out, status) &
        bind(c, name="rbs_table_rebound_many")
      import :: c_int, c_ptr, c_double, c_size_t, c_signed_char, rbs_mix
      type(c_ptr), value :: table
      type(rbs_mix), intent(in) :: mix
      integer(c_size_t), value :: count
      real(c_double), intent(in) :: V(3, *), n(3, *), a(*), u(13, *)
      integer(c_int), value :: interpolation
      real(c_double), intent(out) :: V_out(3, *), Omega_out(3, *)
      integer(c_signed_char), intent(out) :: status(*)
    end subroutine rbs_table_rebound_many

    subroutine rbs_table_rebound_many_rng(table, mix, count, V, n, a, rng, interpolation, V_out, Omega_out, &
        status) bind(c, name="rbs_table_rebound_many_rng")
      import :: c_int, c_ptr, c_double, c_size_t, c_signed_char, rbs_mix, rbs_rng
      type(c_ptr), value :: table
      type(rbs_mix), intent(in) :: mix
      integer(c_size_t), value :: count
      real(c_double), intent(in) :: V(3, *), n(3, *), a(*)
      type(rbs_rng), intent(inout) :: rng
      integer(c_int), value :: interpolation
      real(c_double), intent(out) :: V_out(3, *), Omega_out(3, *)
      integer(c_signed_char), intent(out) :: status(*)
    end subroutine rbs_table_rebound_many_rng

    integer(c_int) function rbs_draw_local(table, mix, alpha1_deg, speed_m_s, u, interpolation, out) &
        bind(c, name="rbs_draw_local")
      import :: c_int, c_ptr, c_double, rbs_mix, RBS_U_PER_DRAW, RBS_LOCAL_SIZE
      type(c_ptr), value :: table
      type(rbs_mix), intent(in) :: mix
      real(c_double), value :: alpha1_deg, speed_m_s
      real(c_double), intent(in) :: u(RBS_U_PER_DRAW)
      integer(c_int), value :: interpolation
      real(c_double), intent(out) :: out(RBS_LOCAL_SIZE)
    end function rbs_draw_local

    ! the direct path alone (the direct model): shape a model code RBS_ELLIPSOID .. RBS_TETRAHEDRON, Omega in rad/s
    integer(c_int) function rbs_direct_rebound(table, shape, V, Omega, n, a, u, V_out, Omega_out) &
        bind(c, name="rbs_direct_rebound")
      import :: c_int, c_ptr, c_double, RBS_U_PER_REBOUND
      type(c_ptr), value :: table
      integer(c_int), value :: shape
      real(c_double), intent(in) :: V(3), Omega(3), n(3)
      real(c_double), value :: a
      real(c_double), intent(in) :: u(RBS_U_PER_REBOUND)
      real(c_double), intent(out) :: V_out(3), Omega_out(3)
    end function rbs_direct_rebound

    ! grain keys (1.2): a particle of key >= 0 hits every wall as the same grain (rebound_scatter.h, "Grain keys")
    integer(c_int) function rbs_rebound_grain(table, mix, key, V, Omega, n, a, u, method, interpolation, V_out, &
        Omega_out) bind(c, name="rbs_rebound_grain")
      import :: c_int, c_int64_t, c_ptr, c_double, rbs_mix, RBS_U_PER_DRAW
      type(c_ptr), value :: table
      type(rbs_mix), intent(in) :: mix
      integer(c_int64_t), value :: key
      real(c_double), intent(in) :: V(3), Omega(3), n(3)
      real(c_double), value :: a
      real(c_double), intent(in) :: u(RBS_U_PER_DRAW)
      integer(c_int), value :: method, interpolation
      real(c_double), intent(out) :: V_out(3), Omega_out(3)
    end function rbs_rebound_grain

    integer(c_int) function rbs_rebound_grain_rng(table, mix, key, V, Omega, n, a, rng, method, interpolation, &
        V_out, Omega_out) bind(c, name="rbs_rebound_grain_rng")
      import :: c_int, c_int64_t, c_ptr, c_double, rbs_mix, rbs_rng
      type(c_ptr), value :: table
      type(rbs_mix), intent(in) :: mix
      integer(c_int64_t), value :: key
      real(c_double), intent(in) :: V(3), Omega(3), n(3)
      real(c_double), value :: a
      type(rbs_rng), intent(inout) :: rng
      integer(c_int), value :: method, interpolation
      real(c_double), intent(out) :: V_out(3), Omega_out(3)
    end function rbs_rebound_grain_rng

    integer(c_int) function rbs_grain_info(table, mix, key, grain) bind(c, name="rbs_grain_info")
      import :: c_int, c_int64_t, c_ptr, rbs_mix, rbs_grain
      type(c_ptr), value :: table
      type(rbs_mix), intent(in) :: mix
      integer(c_int64_t), value :: key
      type(rbs_grain), intent(out) :: grain
    end function rbs_grain_info

    ! seed and ids are uint64 in C: values >= 2**63 are negative here
    integer(c_int64_t) function rbs_grain_key(seed, id1, id2) bind(c, name="rbs_grain_key")
      import :: c_int64_t
      integer(c_int64_t), value :: seed, id1, id2
    end function rbs_grain_key

    ! rbs_rebound_rng under its 0.x name, kept for programs written against 0.x
    integer(c_int) function rbs_rebound_spin(table, mix, V, Omega, n, a, rng, method, interpolation, V_out, &
        Omega_out) bind(c, name="rbs_rebound_spin")
      import :: c_int, c_ptr, c_double, rbs_mix, rbs_rng
      type(c_ptr), value :: table
      type(rbs_mix), intent(in) :: mix
      real(c_double), intent(in) :: V(3), Omega(3), n(3)
      real(c_double), value :: a
      type(rbs_rng), intent(inout) :: rng
      integer(c_int), value :: method, interpolation
      real(c_double), intent(out) :: V_out(3), Omega_out(3)
    end function rbs_rebound_spin

    subroutine rbs_rng_seed(rng, seed) bind(c, name="rbs_rng_seed")
      import :: c_int64_t, rbs_rng
      type(rbs_rng), intent(out) :: rng
      integer(c_int64_t), value :: seed       ! a uint64 in C: seeds >= 2**63 are negative here
    end subroutine rbs_rng_seed

    subroutine rbs_rng_seed_stream(rng, seed, k) bind(c, name="rbs_rng_seed_stream")
      import :: c_int64_t, rbs_rng
      type(rbs_rng), intent(out) :: rng
      integer(c_int64_t), value :: seed, k
    end subroutine rbs_rng_seed_stream

    real(c_double) function rbs_rng_uniform(rng) bind(c, name="rbs_rng_uniform")
      import :: c_double, rbs_rng
      type(rbs_rng), intent(inout) :: rng
    end function rbs_rng_uniform

    subroutine rbs_rng_fill(rng, u, count) bind(c, name="rbs_rng_fill")
      import :: c_double, c_size_t, rbs_rng
      type(rbs_rng), intent(inout) :: rng
      real(c_double), intent(out) :: u(*)
      integer(c_size_t), value :: count
    end subroutine rbs_rng_fill

    type(c_ptr) function rbs_error_string_c(code) bind(c, name="rbs_error_string")
      import :: c_ptr, c_int
      integer(c_int), value :: code
    end function rbs_error_string_c

    integer(c_size_t) function c_strlen(s) bind(c, name="strlen")
      import :: c_ptr, c_size_t
      type(c_ptr), value :: s
    end function c_strlen
  end interface

contains

  ! Open a table: code RBS_OK or an RBS_ERR_*; message (any length) receives the error message.
  integer(c_int) function rbs_open(path, table, message) result(code)
    character(len=*), intent(in) :: path
    type(c_ptr), intent(out) :: table
    character(len=*), intent(out) :: message
    character(kind=c_char) :: buffer(1024)
    integer :: i
    buffer = c_null_char
    code = rbs_table_open(trim(path) // c_null_char, table, buffer, int(size(buffer), c_size_t))
    message = ""
    do i = 1, min(len(message), size(buffer))
      if (buffer(i) == c_null_char) exit
      message(i:i) = buffer(i)
    end do
  end function rbs_open

  ! A mix of one shape ("mix": equal weights); code RBS_OK or RBS_ERR_ARGUMENT.
  integer(c_int) function rbs_mix_from_shape(table, name, mix) result(code)
    type(c_ptr), intent(in) :: table
    character(len=*), intent(in) :: name
    type(rbs_mix), intent(out) :: mix
    character(kind=c_char) :: buffer(512)
    code = rbs_mix_from_shape_c(table, trim(name) // c_null_char, mix, buffer, int(size(buffer), c_size_t))
  end function rbs_mix_from_shape

  ! The equal mix of a table of any number of shapes, sized by the table; not associated if out of memory.
  ! Pass it to the draws as any mix; free it with rbs_mix_free.
  function rbs_mix_new_equal(table) result(mix)
    type(c_ptr), intent(in) :: table
    type(rbs_mix), pointer :: mix
    mix => null()
    call c_f_pointer(rbs_mix_new_equal_c(table), mix)
  end function rbs_mix_new_equal

  ! A mix of one shape of the table ("mix": equal weights), sized by the table; not associated for a name the
  ! table does not hold. Free it with rbs_mix_free.
  function rbs_mix_new_from_shape(table, name) result(mix)
    type(c_ptr), intent(in) :: table
    character(len=*), intent(in) :: name
    type(rbs_mix), pointer :: mix
    character(kind=c_char) :: buffer(512)
    mix => null()
    call c_f_pointer(rbs_mix_new_from_shape_c(table, trim(name) // c_null_char, buffer, &
                                              int(size(buffer), c_size_t)), mix)
  end function rbs_mix_new_from_shape

  ! Free a mix of rbs_mix_new_equal or rbs_mix_new_from_shape (not associated: nothing); mix is nullified.
  subroutine rbs_mix_free(mix)
    type(rbs_mix), pointer, intent(inout) :: mix
    if (associated(mix)) call rbs_mix_free_c(c_loc(mix))
    mix => null()
  end subroutine rbs_mix_free

  ! The description of an error code, as a Fortran string.
  function rbs_error_string(code) result(text)
    integer(c_int), intent(in) :: code
    character(len=:), allocatable :: text
    type(c_ptr) :: p
    character(kind=c_char), pointer :: chars(:)
    integer :: i, length
    p = rbs_error_string_c(code)
    length = int(c_strlen(p))
    call c_f_pointer(p, chars, [length])
    allocate(character(len=length) :: text)
    do i = 1, length
      text(i:i) = chars(i)
    end do
  end function rbs_error_string
end module rebound_scatter
