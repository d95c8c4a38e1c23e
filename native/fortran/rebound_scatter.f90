! rebound_scatter.f90: Fortran bindings (iso_c_binding) to the native runtime of rebound-scatter, version 1.4.
!
! The C functions of rebound_scatter.h, called directly, and bind(c) derived types mirroring its records; units,
! frames and statuses as there (docs/native.md): V in m/s, Omega in rad/s, n a unit normal into the gas, a the
! half-size in m. A thin binding: what C documents holds here.
!
! Records: every record begins with `size`, which the library checks; `call rbs_init(record)` sets it (c_sizeof)
! and the other fields to their defaults (the RBS_*_INIT of C). Pointers in records are type(c_ptr): c_loc of a
! variable with the target attribute, e.g. hit%u = c_loc(u) for real(c_double), target :: u(RBS_U_PER_DRAW), or
! hit%rng = c_loc(rng) for type(rbs_rng), target :: rng. Arrays of many particles are V(3, count): Fortran's
! column-major (3, count) is C's row-major (count, 3). Options may be omitted (the defaults, NULL in C).
!
! Tables and mixes are opaque type(c_ptr) handles. Strings passed to C end with c_null_char: rbs_open,
! rbs_mix_new_from_shape and rbs_mix_new_from_weights do that for you; rbs_c_string turns a C string (a shape's
! name, a status string) into a Fortran one.
!
! Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
module rebound_scatter
  use, intrinsic :: iso_c_binding
  implicit none
  private :: c_strlen, to_message, init_hit, init_options, init_result, init_hits, init_results, init_table_info, &
             init_shape_info, init_wall_info, init_grain

  ! the version of this module (RBS_VERSION_NUMBER of C; Fortran names are case-blind, so rbs_version_number()
  ! is the library's function): compare with rbs_version_number()
  integer(c_int), parameter :: RBS_VERSION_MAJOR = 1, RBS_VERSION_MINOR = 4, RBS_VERSION_PATCH = 0
  integer(c_int), parameter :: RBS_MODULE_VERSION_NUMBER = RBS_VERSION_MAJOR * 1000000 + RBS_VERSION_MINOR * 1000 &
                                                           + RBS_VERSION_PATCH
  integer(c_int), parameter :: RBS_TABLE_FORMAT_MAJOR = 4, RBS_U_PER_DRAW = 13, RBS_TABLE_MAX_SHAPES = 4096
  integer(c_int), parameter :: RBS_SHAPE_NAME_SIZE = 65, RBS_BLOCK = 32, RBS_LOCAL_SIZE = 6
  real(c_double), parameter :: RBS_NORMAL_TOLERANCE = 1e-6_c_double, RBS_SPIN_TOLERANCE = 0.001_c_double
  integer(c_int64_t), parameter :: RBS_NO_KEY = -1_c_int64_t
  ! a rough wall (rbs_options%roughness_deg, rbs_result%wall_hits): the largest roughness (degrees), the default
  ! roughness (the table's wall's), the most facet hits of one hit
  real(c_double), parameter :: RBS_MAX_ROUGHNESS_DEG = 45.0_c_double, RBS_ROUGHNESS_OF_TABLE = -1.0_c_double
  integer(c_int), parameter :: RBS_MAX_WALL_HITS = 10

  ! rbs_status: the one status space of every call and every hit
  integer(c_int), parameter :: RBS_OK = 0, RBS_TRAPPED = 1, RBS_FAILED = 2, RBS_INVALID = -1, RBS_ERR_IO = -2, &
                               RBS_ERR_FORMAT = -3, RBS_ERR_VERSION = -4, RBS_ERR_MEMORY = -5
  ! rbs_method (rbs_options%method), rbs_path (rbs_result%path, rbs_rebound_path)
  integer(c_int), parameter :: RBS_METHOD_AUTO = 0, RBS_METHOD_TABLE = 1, RBS_METHOD_DIRECT = 2
  integer(c_int), parameter :: RBS_PATH_NONE = -1, RBS_PATH_TABLE = 0, RBS_PATH_DIRECT = 1
  ! rbs_interpolation (rbs_options%interpolation)
  integer(c_int), parameter :: RBS_INTERPOLATION_SCALED = 0, RBS_INTERPOLATION_STOCHASTIC = 1
  ! rbs_family, rbs_kind (rbs_shape_info), rbs_dtype (rbs_table_kernel_array)
  integer(c_int), parameter :: RBS_FAMILY_NONE = -1, RBS_FAMILY_ELLIPSOID = 0, RBS_FAMILY_PRISM = 1, &
                               RBS_FAMILY_CUT_PRISM = 2, RBS_FAMILY_TETRAHEDRON = 3
  integer(c_int), parameter :: RBS_KIND_SMOOTH = 0, RBS_KIND_POLYHEDRON = 1
  integer(c_int), parameter :: RBS_DTYPE_FLOAT64 = 0, RBS_DTYPE_FLOAT32 = 1

  ! one xoshiro256+ state (rbs_rng): one per thread / MPI rank, owned by the caller
  type, bind(c) :: rbs_rng
    integer(c_int64_t) :: s(4) = 0
  end type rbs_rng

  ! one hit, global frame (rbs_hit)
  type, bind(c) :: rbs_hit
    integer(c_size_t) :: size = 0
    real(c_double) :: V(3) = 0.0_c_double          ! incident velocity, m/s (moving into the wall)
    real(c_double) :: Omega(3) = 0.0_c_double      ! incident angular velocity, rad/s
    real(c_double) :: n(3) = 0.0_c_double          ! unit wall normal into the gas
    real(c_double) :: a = 0.0_c_double             ! half-size, m
    integer(c_int64_t) :: grain_key = RBS_NO_KEY   ! RBS_NO_KEY, or the particle's grain key >= 0
    type(c_ptr) :: u = c_null_ptr                  ! RBS_U_PER_DRAW uniforms in [0, 1), or c_null_ptr: from rng
    type(c_ptr) :: rng = c_null_ptr                ! a type(rbs_rng), advanced by RBS_U_PER_DRAW uniforms
  end type rbs_hit

  ! how hits are answered (rbs_options; omitted: these defaults)
  type, bind(c) :: rbs_options
    integer(c_size_t) :: size = 0
    integer(c_int) :: method = RBS_METHOD_AUTO
    integer(c_int) :: interpolation = RBS_INTERPOLATION_SCALED
    real(c_double) :: roughness_deg = RBS_ROUGHNESS_OF_TABLE  ! degrees: < 0 the table's, 0 smooth, (0, 45] rough
  end type rbs_options

  ! what a hit did (rbs_result; NaN vectors unless the status is RBS_OK)
  type, bind(c) :: rbs_result
    integer(c_size_t) :: size = 0
    integer(c_int) :: status = RBS_INVALID, path = RBS_PATH_NONE
    integer(c_int) :: shape = -1                   ! the table's shape index (0-based)
    integer(c_int) :: n_collisions = -1            ! direct path: collisions of the rebound; table path: -1
    real(c_double) :: V(3) = 0.0_c_double, Omega(3) = 0.0_c_double
    integer(c_int) :: wall_hits = 0                ! hits on the wall: 1 smooth, 1 to RBS_MAX_WALL_HITS rough
    ! the work of the hit on the wall per unit particle mass, m**2/s**2, normal and tangential (either path; NaN from
    ! a table of format 4.0 on the table path, and for RBS_INVALID)
    real(c_double) :: wall_work_normal = 0.0_c_double, wall_work_tangential = 0.0_c_double
  end type rbs_result

  ! many hits from the table (rbs_hits): c_loc of V(3, count), n(3, count), a(count), u(RBS_U_PER_DRAW, count)
  type, bind(c) :: rbs_hits
    integer(c_size_t) :: size = 0
    integer(c_size_t) :: count = 0
    type(c_ptr) :: V = c_null_ptr, n = c_null_ptr, a = c_null_ptr
    type(c_ptr) :: u = c_null_ptr                  ! or c_null_ptr: from rng
    type(c_ptr) :: rng = c_null_ptr
  end type rbs_hits

  ! their outputs (rbs_results): c_loc of V(3, count), Omega(3, count), status(count) (integer(c_signed_char))
  type, bind(c) :: rbs_results
    integer(c_size_t) :: size = 0
    type(c_ptr) :: V = c_null_ptr, Omega = c_null_ptr, status = c_null_ptr
  end type rbs_results

  ! sizes, grids' ranges and provenance of a table (rbs_table_info)
  type, bind(c) :: rbs_table_info
    integer(c_size_t) :: size = 0
    integer(c_int) :: n_shapes = 0, n_alpha1 = 0, n_speed = 0, n_clusters = 0, n_levels = 0, n_dictionary = 0, &
                      n_pieces = 0, format_major = 0, format_minor = 0
    integer(c_long_long) :: particles_per_cell = 0, n_max = 0
    real(c_double) :: alpha1_min_deg = 0.0_c_double, alpha1_max_deg = 0.0_c_double
    real(c_double) :: speed_min_m_s = 0.0_c_double, speed_max_m_s = 0.0_c_double
    integer(c_size_t) :: kernel_bytes = 0
  end type rbs_table_info

  ! one shape of a table (rbs_shape_info): name a C string (rbs_c_string), vertices (3, n_vertices) c_f_pointer
  type, bind(c) :: rbs_shape_info
    integer(c_size_t) :: size = 0
    type(c_ptr) :: name = c_null_ptr
    integer(c_int) :: kind = 0, family = 0, n_vertices = 0
    type(c_ptr) :: vertices = c_null_ptr
    real(c_double) :: inertia(3) = 0.0_c_double, aspect(4) = 0.0_c_double
    integer(c_int) :: both_hands = 0
  end type rbs_shape_info

  ! the wall of a table (rbs_wall_info): family and name C strings, n_parameters names (C strings) and values; a
  ! tabulated law's nodes and a_nc (c_f_pointer: restitution as (n_contact_sines, n_contact_speeds), C's row-major)
  type, bind(c) :: rbs_wall_info
    integer(c_size_t) :: size = 0
    type(c_ptr) :: family = c_null_ptr, name = c_null_ptr
    integer(c_int) :: n_parameters = 0
    type(c_ptr) :: parameter_names = c_null_ptr, parameter_values = c_null_ptr
    real(c_double) :: speed_range_m_s(2) = 0.0_c_double   ! the |V-| (m/s) the law holds over; (0, +inf): not stated
    integer(c_int) :: n_contact_speeds = 0                 ! 0 (and null pointers) for the exponential family
    type(c_ptr) :: contact_speed_m_s = c_null_ptr         ! |V_c-| nodes, m/s
    integer(c_int) :: n_contact_sines = 0
    type(c_ptr) :: contact_sine = c_null_ptr              ! |v_c-|/|V_c-| nodes, from 0 to 1
    type(c_ptr) :: restitution = c_null_ptr               ! a_nc at the nodes
    real(c_double) :: roughness_deg = 0.0_c_double        ! the wall's roughness, degrees; 0: smooth
  end type rbs_wall_info

  ! one grain of a table's mix (rbs_grain): its table shape index (0-based), the b/a, c/b and hand the direct path
  ! gives it (NaN where the key does not draw them)
  type, bind(c) :: rbs_grain
    integer(c_size_t) :: size = 0
    integer(c_int) :: shape = -1
    real(c_double) :: ratio_ba = 0.0_c_double, ratio_cb = 0.0_c_double, hand = 0.0_c_double
  end type rbs_grain

  ! size and defaults of a record: call rbs_init(record)
  interface rbs_init
    module procedure init_hit, init_options, init_result, init_hits, init_results, init_table_info, &
                     init_shape_info, init_wall_info, init_grain
  end interface rbs_init

  interface
    ! ------------------------------------------------------------ every wall hit
    integer(c_int) function rbs_rebound(table, mix, hit, options, result) bind(c, name="rbs_rebound")
      import :: c_int, c_ptr, rbs_hit, rbs_options, rbs_result
      type(c_ptr), value :: table, mix
      type(rbs_hit), intent(in) :: hit
      type(rbs_options), intent(in), optional :: options
      type(rbs_result), intent(inout) :: result
    end function rbs_rebound

    integer(c_int) function rbs_rebound_path(table, hit, options) bind(c, name="rbs_rebound_path")
      import :: c_int, c_ptr, rbs_hit, rbs_options
      type(c_ptr), value :: table
      type(rbs_hit), intent(in) :: hit
      type(rbs_options), intent(in), optional :: options
    end function rbs_rebound_path

    ! ------------------------------------------------------------ many hits from the table
    integer(c_int) function rbs_draw_many(table, mix, hits, options, results) bind(c, name="rbs_draw_many")
      import :: c_int, c_ptr, rbs_hits, rbs_options, rbs_results
      type(c_ptr), value :: table, mix
      type(rbs_hits), intent(in) :: hits
      type(rbs_options), intent(in), optional :: options
      type(rbs_results), intent(in) :: results
    end function rbs_draw_many

    subroutine rbs_draw_many_uniforms(rng, count, u) bind(c, name="rbs_draw_many_uniforms")
      import :: c_size_t, c_double, rbs_rng
      type(rbs_rng), intent(inout) :: rng
      integer(c_size_t), value :: count
      real(c_double), intent(out) :: u(*)
    end subroutine rbs_draw_many_uniforms

    integer(c_int) function rbs_draw_local(table, mix, alpha1_deg, speed_m_s, u, options, out) &
        bind(c, name="rbs_draw_local")
      import :: c_int, c_ptr, c_double, rbs_options, RBS_U_PER_DRAW, RBS_LOCAL_SIZE
      type(c_ptr), value :: table, mix
      real(c_double), value :: alpha1_deg, speed_m_s
      real(c_double), intent(in) :: u(RBS_U_PER_DRAW)
      type(rbs_options), intent(in), optional :: options
      real(c_double), intent(out) :: out(RBS_LOCAL_SIZE)
    end function rbs_draw_local

    ! ------------------------------------------------------------ tables
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

    type(c_ptr) function rbs_table_path(table) bind(c, name="rbs_table_path")
      import :: c_ptr
      type(c_ptr), value :: table
    end function rbs_table_path

    integer(c_int) function rbs_table_info_get(table, info) bind(c, name="rbs_table_info_get")
      import :: c_int, c_ptr, rbs_table_info
      type(c_ptr), value :: table
      type(rbs_table_info), intent(inout) :: info
    end function rbs_table_info_get

    type(c_ptr) function rbs_table_alpha1_grid(table, count) bind(c, name="rbs_table_alpha1_grid")
      import :: c_int, c_ptr
      type(c_ptr), value :: table
      integer(c_int), intent(out) :: count
    end function rbs_table_alpha1_grid

    type(c_ptr) function rbs_table_speed_grid(table, count) bind(c, name="rbs_table_speed_grid")
      import :: c_int, c_ptr
      type(c_ptr), value :: table
      integer(c_int), intent(out) :: count
    end function rbs_table_speed_grid

    integer(c_int) function rbs_table_n_shapes(table) bind(c, name="rbs_table_n_shapes")
      import :: c_int, c_ptr
      type(c_ptr), value :: table
    end function rbs_table_n_shapes

    ! shape i (0-based): a C string (rbs_c_string), c_null_ptr out of range
    type(c_ptr) function rbs_table_shape_name(table, i) bind(c, name="rbs_table_shape_name")
      import :: c_int, c_ptr
      type(c_ptr), value :: table
      integer(c_int), value :: i
    end function rbs_table_shape_name

    integer(c_int) function rbs_table_shape_info(table, i, info) bind(c, name="rbs_table_shape_info")
      import :: c_int, c_ptr, rbs_shape_info
      type(c_ptr), value :: table
      integer(c_int), value :: i
      type(rbs_shape_info), intent(inout) :: info
    end function rbs_table_shape_info

    integer(c_int) function rbs_table_wall(table, info) bind(c, name="rbs_table_wall")
      import :: c_int, c_ptr, rbs_wall_info
      type(c_ptr), value :: table
      type(rbs_wall_info), intent(inout) :: info
    end function rbs_table_wall

    ! name: a C string (e.g. "cells" // c_null_char); data points into the table
    integer(c_int) function rbs_table_kernel_array(table, name, data, count, dtype) &
        bind(c, name="rbs_table_kernel_array")
      import :: c_int, c_ptr, c_char, c_size_t
      type(c_ptr), value :: table
      character(kind=c_char), dimension(*), intent(in) :: name
      type(c_ptr), intent(out) :: data
      integer(c_size_t), intent(out) :: count
      integer(c_int), intent(out) :: dtype
    end function rbs_table_kernel_array

    ! ------------------------------------------------------------ shape mixes (opaque: type(c_ptr))
    type(c_ptr) function rbs_mix_new_equal(table) bind(c, name="rbs_mix_new_equal")
      import :: c_ptr
      type(c_ptr), value :: table
    end function rbs_mix_new_equal

    type(c_ptr) function rbs_mix_new_from_shape_c(table, name, message, message_size) &
        bind(c, name="rbs_mix_new_from_shape")
      import :: c_ptr, c_char, c_size_t
      type(c_ptr), value :: table
      character(kind=c_char), dimension(*), intent(in) :: name
      character(kind=c_char), dimension(*), intent(inout) :: message
      integer(c_size_t), value :: message_size
    end function rbs_mix_new_from_shape_c

    type(c_ptr) function rbs_mix_new_from_weights_c(table, n, names, weights, message, message_size) &
        bind(c, name="rbs_mix_new_from_weights")
      import :: c_ptr, c_int, c_char, c_double, c_size_t
      type(c_ptr), value :: table
      integer(c_int), value :: n
      type(c_ptr), intent(in) :: names(*)
      real(c_double), intent(in) :: weights(*)
      character(kind=c_char), dimension(*), intent(inout) :: message
      integer(c_size_t), value :: message_size
    end function rbs_mix_new_from_weights_c

    subroutine rbs_mix_free(mix) bind(c, name="rbs_mix_free")
      import :: c_ptr
      type(c_ptr), value :: mix
    end subroutine rbs_mix_free

    ! ------------------------------------------------------------ grain keys
    integer(c_int) function rbs_grain_info(table, mix, key, grain) bind(c, name="rbs_grain_info")
      import :: c_int, c_int64_t, c_ptr, rbs_grain
      type(c_ptr), value :: table, mix
      integer(c_int64_t), value :: key
      type(rbs_grain), intent(inout) :: grain
    end function rbs_grain_info

    ! seed and ids are uint64 in C: values >= 2**63 are negative here
    integer(c_int64_t) function rbs_grain_key(seed, id1, id2) bind(c, name="rbs_grain_key")
      import :: c_int64_t
      integer(c_int64_t), value :: seed, id1, id2
    end function rbs_grain_key

    ! ------------------------------------------------------------ random numbers
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

    ! ------------------------------------------------------------ the library
    type(c_ptr) function rbs_status_string_c(status) bind(c, name="rbs_status_string")
      import :: c_ptr, c_int
      integer(c_int), value :: status
    end function rbs_status_string_c

    type(c_ptr) function rbs_version_c() bind(c, name="rbs_version")
      import :: c_ptr
    end function rbs_version_c

    integer(c_int) function rbs_version_number() bind(c, name="rbs_version_number")
      import :: c_int
    end function rbs_version_number

    integer(c_size_t) function c_strlen(s) bind(c, name="strlen")
      import :: c_ptr, c_size_t
      type(c_ptr), value :: s
    end function c_strlen
  end interface

contains

  subroutine init_hit(record)
    type(rbs_hit), intent(out) :: record
    record%size = c_sizeof(record)
  end subroutine init_hit

  subroutine init_options(record)
    type(rbs_options), intent(out) :: record
    record%size = c_sizeof(record)
  end subroutine init_options

  subroutine init_result(record)
    type(rbs_result), intent(out) :: record
    record%size = c_sizeof(record)
  end subroutine init_result

  subroutine init_hits(record)
    type(rbs_hits), intent(out) :: record
    record%size = c_sizeof(record)
  end subroutine init_hits

  subroutine init_results(record)
    type(rbs_results), intent(out) :: record
    record%size = c_sizeof(record)
  end subroutine init_results

  subroutine init_table_info(record)
    type(rbs_table_info), intent(out) :: record
    record%size = c_sizeof(record)
  end subroutine init_table_info

  subroutine init_shape_info(record)
    type(rbs_shape_info), intent(out) :: record
    record%size = c_sizeof(record)
  end subroutine init_shape_info

  subroutine init_wall_info(record)
    type(rbs_wall_info), intent(out) :: record
    record%size = c_sizeof(record)
  end subroutine init_wall_info

  subroutine init_grain(record)
    type(rbs_grain), intent(out) :: record
    record%size = c_sizeof(record)
  end subroutine init_grain

  ! A C string (NUL-terminated; c_null_ptr: "") as a Fortran string.
  function rbs_c_string(p) result(text)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: text
    character(kind=c_char), pointer :: chars(:)
    integer :: i, length
    length = 0
    if (c_associated(p)) length = int(c_strlen(p))
    allocate(character(len=length) :: text)
    if (length == 0) return
    call c_f_pointer(p, chars, [length])
    do i = 1, length
      text(i:i) = chars(i)
    end do
  end function rbs_c_string

  ! C's message buffer into a Fortran string
  subroutine to_message(buffer, message)
    character(kind=c_char), intent(in) :: buffer(:)
    character(len=*), intent(out) :: message
    integer :: i
    message = ""
    do i = 1, min(len(message), size(buffer))
      if (buffer(i) == c_null_char) exit
      message(i:i) = buffer(i)
    end do
  end subroutine to_message

  ! Open a table: RBS_OK or a refusal (< 0); message (any length) receives the error message.
  integer(c_int) function rbs_open(path, table, message) result(code)
    character(len=*), intent(in) :: path
    type(c_ptr), intent(out) :: table
    character(len=*), intent(out) :: message
    character(kind=c_char) :: buffer(1024)
    buffer = c_null_char
    code = rbs_table_open(trim(path) // c_null_char, table, buffer, int(size(buffer), c_size_t))
    call to_message(buffer, message)
  end function rbs_open

  ! A mix of one shape of the table ("mix": equal weights); c_null_ptr (and the message) for a name the table does
  ! not hold. Free it with rbs_mix_free.
  function rbs_mix_new_from_shape(table, name, message) result(mix)
    type(c_ptr), intent(in) :: table
    character(len=*), intent(in) :: name
    character(len=*), intent(out), optional :: message
    type(c_ptr) :: mix
    character(kind=c_char) :: buffer(512)
    buffer = c_null_char
    mix = rbs_mix_new_from_shape_c(table, trim(name) // c_null_char, buffer, int(size(buffer), c_size_t))
    if (present(message)) call to_message(buffer, message)
  end function rbs_mix_new_from_shape

  ! A mix of named weights (names(i) trimmed); c_null_ptr (and the message) for a bad name or weight. Free it with
  ! rbs_mix_free.
  function rbs_mix_new_from_weights(table, names, weights, message) result(mix)
    type(c_ptr), intent(in) :: table
    character(len=*), intent(in) :: names(:)
    real(c_double), intent(in) :: weights(:)
    character(len=*), intent(out), optional :: message
    type(c_ptr) :: mix
    character(kind=c_char), allocatable, target :: text(:, :)
    type(c_ptr), allocatable :: pointers(:)
    character(kind=c_char) :: buffer(512)
    integer :: i, k, length
    allocate(text(len(names) + 1, max(size(names), 1)), pointers(max(size(names), 1)))
    text = c_null_char
    do i = 1, size(names)
      length = len_trim(names(i))
      do k = 1, length
        text(k, i) = names(i)(k:k)
      end do
      pointers(i) = c_loc(text(1, i))
    end do
    buffer = c_null_char
    mix = rbs_mix_new_from_weights_c(table, int(size(names), c_int), pointers, weights, buffer, &
                                     int(size(buffer), c_size_t))
    if (present(message)) call to_message(buffer, message)
  end function rbs_mix_new_from_weights

  ! The description of a status, as a Fortran string.
  function rbs_status_string(status) result(text)
    integer(c_int), intent(in) :: status
    character(len=:), allocatable :: text
    text = rbs_c_string(rbs_status_string_c(status))
  end function rbs_status_string

  ! The library's version, "MAJOR.MINOR.PATCH".
  function rbs_version() result(text)
    character(len=:), allocatable :: text
    text = rbs_c_string(rbs_version_c())
  end function rbs_version
end module rebound_scatter
