!> Fortran 2008 interface to libmpmc (explicit MPM with the F-bar method of Zhao, Jiang &
!> Choo 2023).
!>
!> Every binding is a bind(C) interface to the C symbol of the same name in mpmc.h: no name
!> mangling, no handle tables.  Handles are typed wrappers around a C pointer, so passing a
!> simulation where a context is expected is a compile error.  Results are integer(c_int),
!> 0 (MPMC_SUCCESS) on success; mpmc_context_last_error(ctx) returns the message of the last
!> failure as an ordinary Fortran string.
!>
!> Conventions that differ from ordinary Fortran, because they are C's:
!>  - ids and point indices are 0-based (material ids, wall ids, `first`, particle sets);
!>  - a particle field is x(ncomp, np) with column p the C row p-1 (no copy: it aliases the
!>    library's storage and is valid until points are added, the field goes with what needs it
!>    (Jbar with F-bar set off, the pore pressure with the water table removed) or the
!>    simulation is destroyed; over MPI borrow again after each step, which may migrate points);
!>  - the relative deformation gradient handed to a user material is C row-major, so the
!>    Fortran array dF(3,3) holds the transpose: F_ij = dF(j, i).
!> Strings are ordinary character(*) in the wrappers; a few functions that live in other
!> libraries (mpmc_seed_gmsh in libmpmc_gmsh) take a C string: pass mpmc_c_str('...').
module mpmc
  use, intrinsic :: iso_c_binding, only: c_int, c_int64_t, c_double, c_char, c_ptr, c_funptr, &
    c_long, c_null_ptr, c_null_char, c_size_t, c_associated, c_f_pointer, c_loc
  implicit none
  private

  ! ---- error codes (mpmc.h MPMC_ERROR_LIST) -------------------------------------------------
  integer(c_int), parameter, public :: MPMC_SUCCESS = 0, MPMC_ERR_ARG = 1, MPMC_ERR_MEMORY = 2, &
    MPMC_ERR_STATE = 3, MPMC_ERR_OUTSIDE = 4, MPMC_ERR_NUMERIC = 5, MPMC_ERR_UNSTABLE = 6, &
    MPMC_ERR_SOLVER = 7, MPMC_ERR_IO = 8, MPMC_ERR_FORMAT = 9, MPMC_ERR_UNSUPPORTED = 10, &
    MPMC_ERROR_COUNT = 11
  integer(c_int), parameter, public :: MPMC_VERSION_MAJOR = 0, MPMC_VERSION_MINOR = 1, &
    MPMC_VERSION_PATCH = 0
  ! log levels
  integer(c_int), parameter, public :: MPMC_LOG_SILENT = 0, MPMC_LOG_ERROR = 1, &
    MPMC_LOG_WARNING = 2, MPMC_LOG_INFO = 3, MPMC_LOG_DEBUG = 4
  ! bases
  integer(c_int), parameter, public :: MPMC_BASIS_LINEAR = 0, MPMC_BASIS_UGIMP = 1, &
    MPMC_BASIS_BSPLINE2 = 2, MPMC_BASIS_BSPLINE3 = 3
  ! F-bar projection: off, Algorithm 1 as published, projection of det F, projection of
  ! det F onto a space one order below the basis
  integer(c_int), parameter, public :: MPMC_FBAR_OFF = 0, MPMC_FBAR_PAPER = 1, &
    MPMC_FBAR_TOTAL = 2, MPMC_FBAR_STABLE = 3, MPMC_FBAR_ANCHORED = 4
  ! walls
  integer(c_int), parameter, public :: MPMC_WALL_FIXED = 0, MPMC_WALL_SLIP = 1, &
    MPMC_WALL_SEPARABLE = 2
  ! local solvers
  integer(c_int), parameter, public :: MPMC_SOLVER_AUTO = 0, MPMC_SOLVER_NEWTON = 1, &
    MPMC_SOLVER_KINSOL = 2
  ! instruction set of the transfer kernels (baseline and avx2 the same results to the bit;
  ! fma, fused multiply-adds: round-off apart; avx512, fma for AVX-512 with fma's bits, the
  ! default where the processor has AVX-512, else fma where it has AVX2)
  integer(c_int), parameter, public :: MPMC_KERNELS_AUTO = 0, MPMC_KERNELS_BASELINE = 1, &
    MPMC_KERNELS_AVX2 = 2, MPMC_KERNELS_FMA = 3, MPMC_KERNELS_AVX512 = 4
  ! particle fields
  integer(c_int), parameter, public :: MPMC_FIELD_POSITION = 0, MPMC_FIELD_VELOCITY = 1, &
    MPMC_FIELD_MASS = 2, MPMC_FIELD_VOLUME0 = 3, MPMC_FIELD_J = 4, MPMC_FIELD_JBAR = 5, &
    MPMC_FIELD_STRESS = 6, MPMC_FIELD_BE = 7, MPMC_FIELD_EPS_P = 8, MPMC_FIELD_FORCE = 9, &
    MPMC_FIELD_X0 = 10, MPMC_FIELD_REGION = 11, MPMC_FIELD_PORE_PRESSURE = 12, &
    MPMC_FIELD_COUNT = 13
  ! phases of a step: stats%phase_seconds(MPMC_PHASE_P2G) (indexed from 0, as in C)
  integer(c_int), parameter, public :: MPMC_PHASE_SORT = 0, MPMC_PHASE_SLABS = 1, &
    MPMC_PHASE_P2G = 2, MPMC_PHASE_GRID = 3, MPMC_PHASE_G2P = 4, MPMC_PHASE_FBAR = 5, &
    MPMC_PHASE_STRESS = 6, MPMC_PHASE_CHECKS = 7, MPMC_PHASE_COUNT = 8
  ! seeding from gmsh
  integer(c_int), parameter, public :: MPMC_SEED_LATTICE = 0, MPMC_SEED_QUADRATURE = 1
  ! mpmc_workflow_run flags
  integer(c_int), parameter, public :: MPMC_WORKFLOW_FORCE = 1, MPMC_WORKFLOW_QUIET = 2, &
    MPMC_WORKFLOW_CHECK = 4, MPMC_WORKFLOW_FOS = 8
  !> The run monitor's default energy factor (mpmc_sim_set_energy_monitor).
  real(c_double), parameter, public :: MPMC_MONITOR_ENERGY_FACTOR = 10.0_c_double
  !> The paper's strength reduction factor (landslide trigger), for mpmc_sim_reduce_strength.
  real(c_double), parameter, public :: MPMC_DEFAULT_STRENGTH_REDUCTION = 1.65_c_double

  ! ---- typed handles --------------------------------------------------------------------
  type, bind(C), public :: mpmc_context
    type(c_ptr) :: ptr = c_null_ptr
  end type mpmc_context
  type, bind(C), public :: mpmc_sim
    type(c_ptr) :: ptr = c_null_ptr
  end type mpmc_sim
  type, bind(C), public :: mpmc_output
    type(c_ptr) :: ptr = c_null_ptr
  end type mpmc_output

  !> Run statistics (mpmc_stats).
  type, bind(C), public :: mpmc_stats
    integer(c_int64_t) :: steps = 0
    real(c_double) :: time = 0
    integer(c_int64_t) :: particle_steps = 0
    integer(c_int64_t) :: return_maps = 0
    integer(c_int64_t) :: kinsol_fallbacks = 0
    real(c_double) :: wall_seconds = 0
    !> wall_seconds by phase, indexed by MPMC_PHASE_* (sort, slabs, p2g, grid, g2p, fbar,
    !> stress, checks)
    real(c_double) :: phase_seconds(0:7) = 0
  end type mpmc_stats

  !> A user material's stress update (mpmc_user_stress_fn).  Called from several threads at
  !> once: declare it recursive and keep no SAVE'd (or module) scratch.  dF(j, i) = F_ij.
  abstract interface
    function mpmc_user_stress_fn(data, dF, dt, state, stress) bind(C) result(ierr)
      import :: c_ptr, c_double, c_int
      type(c_ptr), value :: data
      real(c_double), intent(in) :: dF(3, 3)
      real(c_double), value :: dt
      real(c_double), intent(inout) :: state(*)
      real(c_double), intent(inout) :: stress(6)
      integer(c_int) :: ierr
    end function mpmc_user_stress_fn
  end interface
  public :: mpmc_user_stress_fn

  !> Drucker-Prager's fit to Mohr-Coulomb (mpmc_dp_match)
  integer(c_int), parameter, public :: MPMC_DP_MATCH_COMPRESSION = 0, &
    MPMC_DP_MATCH_EXTENSION = 1, MPMC_DP_MATCH_PLANE_STRAIN = 2
  !> The largest number of parameters of a model (mpmc_sim_get_material's par)
  integer(c_int), parameter, public :: MPMC_MAX_PARAMS = 16

  !> What a user yield surface gives at (tau, alpha) (mpmc_yield_eval): Voigt xx yy zz yz xz
  !> xy, tensor components; drdtau(j, i) = d r_i / d tau_j (C's row-major [6 i + j]).
  type, bind(C), public :: mpmc_yield_eval
    real(c_double) :: f = 0
    real(c_double) :: dfdtau(6) = 0
    real(c_double) :: dfdalpha = 0
    real(c_double) :: r(6) = 0
    real(c_double) :: drdtau(6, 6) = 0
    real(c_double) :: drdalpha(6) = 0
  end type mpmc_yield_eval

  !> A user yield surface (mpmc_yield_fn): fill out at the Kirchhoff stress tau and the
  !> hardening variable alpha.  Called from several threads at once: declare it recursive.
  abstract interface
    function mpmc_yield_fn(data, tau, alpha, out) bind(C) result(ierr)
      import :: c_ptr, c_double, c_int, mpmc_yield_eval
      type(c_ptr), value :: data
      real(c_double), intent(in) :: tau(6)
      real(c_double), value :: alpha
      type(mpmc_yield_eval), intent(out) :: out
      integer(c_int) :: ierr
    end function mpmc_yield_fn
  end interface
  public :: mpmc_yield_fn

  !> A model of the material table (mpmc_model_info); the strings through mpmc_f_string.
  type, bind(C), public :: mpmc_model_info
    type(c_ptr) :: name = c_null_ptr, doc = c_null_ptr
    integer(c_int) :: nparam = 0, nstore = 0, plastic = 0, needs_function = 0
  end type mpmc_model_info
  !> One of its parameters (mpmc_param_info)
  type, bind(C), public :: mpmc_param_info
    type(c_ptr) :: name = c_null_ptr, unit = c_null_ptr, doc = c_null_ptr
    real(c_double) :: lo = 0, hi = 0
    integer(c_int) :: lo_open = 0, hi_open = 0, optional = 0
    real(c_double) :: def = 0
    integer(c_int) :: default_of = -1, at_most = -1, alias_of = -1
    real(c_double) :: scale = 1
    integer(c_int) :: strength = 0, nwords = 0
    type(c_ptr) :: words = c_null_ptr
  end type mpmc_param_info

  ! ---- public procedures: direct bindings (same name as the C symbol) ----------------------
  public :: mpmc_context_create, mpmc_context_destroy, mpmc_context_clear_error, &
    mpmc_context_set_log_level, mpmc_version
  public :: mpmc_sim_create, mpmc_sim_destroy, mpmc_sim_get_context, mpmc_sim_get_dim, &
    mpmc_sim_set_grid, mpmc_sim_get_grid, mpmc_sim_set_basis, mpmc_sim_set_fbar, &
    mpmc_sim_get_fbar, mpmc_sim_set_flip_blend, mpmc_sim_set_pic_diffusivity, mpmc_sim_set_gravity, &
    mpmc_sim_set_damping, mpmc_sim_set_kinetic_damping, mpmc_sim_set_adaptive_damping, &
    mpmc_sim_get_adaptive_damping, mpmc_sim_set_solver, mpmc_sim_set_threads, &
    mpmc_sim_set_kernels, mpmc_sim_get_kernels, mpmc_sim_set_water_table, &
    mpmc_sim_set_water_table_plane, mpmc_sim_set_geostatic_stress
  ! MPI builds only (libmpmc/include/mpmc_mpi.h): comm is MPI's Fortran handle, the integer
  ! of the mpi module or mpi_f08's comm%MPI_VAL
  public :: mpmc_sim_create_mpi_f, mpmc_sim_get_mpi_slab, mpmc_sim_get_mpi_traffic, &
    mpmc_sim_set_mpi_balance, mpmc_sim_get_mpi_imbalance, mpmc_sim_checkpoint_read_mpi_f
  public :: mpmc_sim_add_material_neo_hookean, mpmc_sim_add_material_hencky, &
    mpmc_sim_add_material_hencky_j2, mpmc_sim_add_material_hencky_j2_su, &
    mpmc_sim_add_material_newtonian, mpmc_sim_get_num_materials, mpmc_sim_reduce_strength, &
    mpmc_sim_add_material_user, mpmc_sim_set_material_user_fn, &
    mpmc_sim_add_material_mohr_coulomb, mpmc_sim_add_material_drucker_prager, &
    mpmc_sim_add_material_user_yield, mpmc_sim_set_material_yield_fn, &
    mpmc_sim_set_strength_reduction, mpmc_sim_get_material, mpmc_model_count, &
    mpmc_model_get_info, mpmc_model_get_param
  public :: mpmc_model_find, mpmc_sim_add_material, mpmc_f_string
  public :: mpmc_sim_add_rigid_box, mpmc_sim_add_rigid_polygon, mpmc_sim_remove_rigid, &
    mpmc_sim_set_rigid_velocity, mpmc_sim_get_rigid_offset, mpmc_sim_get_rigid_reaction, &
    mpmc_sim_get_rigid_gap, mpmc_sim_set_contact_params, mpmc_sim_get_contact_params
  public :: mpmc_sim_add_particles, mpmc_sim_get_num_particles, mpmc_sim_set_particle_forces
  public :: mpmc_sim_set_sort_interval, mpmc_sim_get_sort_interval, mpmc_sim_sort_particles
  public :: mpmc_sim_add_wall, mpmc_sim_add_wall_face, mpmc_sim_add_wall_box, &
    mpmc_sim_add_wall_nodes, mpmc_sim_remove_wall
  public :: mpmc_sim_stable_dt, mpmc_sim_step, mpmc_sim_set_force_dt, mpmc_sim_get_time, &
    mpmc_sim_set_time, mpmc_sim_get_kinetic_energy, mpmc_sim_get_stats, &
    mpmc_sim_set_energy_monitor
  public :: mpmc_sim_get_num_particle_sets, mpmc_sim_get_num_node_sets, mpmc_sim_seed_box, &
    mpmc_sim_seed_polygon, mpmc_seed_gmsh
  public :: mpmc_output_write, mpmc_output_destroy, mpmc_free
  ! ---- public procedures: Fortran wrappers (strings, zero-copy arrays) -------------------
  public :: mpmc_error_string, mpmc_context_last_error, mpmc_context_get_last_error
  public :: mpmc_context_get_last_code, mpmc_context_set_error
  public :: mpmc_phase_name, mpmc_kernels_name
  public :: mpmc_sim_get_field, mpmc_sim_restore_field, mpmc_sim_get_material_ids, &
    mpmc_sim_get_particle_ids, mpmc_sim_get_user_state
  public :: mpmc_sim_add_particle_set, mpmc_sim_get_particle_set, mpmc_sim_find_particle_set
  public :: mpmc_sim_add_node_set, mpmc_sim_get_node_set, mpmc_sim_find_node_set
  public :: mpmc_output_create, mpmc_sim_checkpoint_write, mpmc_sim_checkpoint_read
  public :: mpmc_workflow_run, mpmc_workflow_resume
  public :: mpmc_c_str
  ! ---- public procedures: Fortran-only conveniences ------------------------------------
  public :: mpmc_sim_run_stage

  !> Borrow a particle field without a copy: x(ncomp, np) (rank 2) or x(ncomp*np) (rank 1).
  interface mpmc_sim_get_field
    module procedure get_field_2d, get_field_1d
  end interface mpmc_sim_get_field
  !> Give a borrowed field back; the Fortran pointer is nullified.
  interface mpmc_sim_restore_field
    module procedure restore_field_2d, restore_field_1d
  end interface mpmc_sim_restore_field

  interface
    ! ---- errors and context ---------------------------------------------------------------
    function mpmc_error_string_c(code) bind(C, name='mpmc_error_string') result(s)
      import :: c_int, c_ptr
      integer(c_int), value :: code
      type(c_ptr) :: s
    end function
    function mpmc_phase_name_c(phase) bind(C, name='mpmc_phase_name') result(s)
      import :: c_int, c_ptr
      integer(c_int), value :: phase
      type(c_ptr) :: s
    end function
    function mpmc_kernels_name_c(kernels) bind(C, name='mpmc_kernels_name') result(s)
      import :: c_int, c_ptr
      integer(c_int), value :: kernels
      type(c_ptr) :: s
    end function
    function mpmc_context_create(ctx) bind(C, name='mpmc_context_create') result(ierr)
      import :: c_int, mpmc_context
      type(mpmc_context), intent(out) :: ctx
      integer(c_int) :: ierr
    end function
    function mpmc_context_destroy(ctx) bind(C, name='mpmc_context_destroy') result(ierr)
      import :: c_int, mpmc_context
      type(mpmc_context), intent(inout) :: ctx
      integer(c_int) :: ierr
    end function
    function mpmc_context_get_last_error_c(ctx, buf, len) &
        bind(C, name='mpmc_context_get_last_error') result(ierr)
      import :: c_int, c_char, mpmc_context
      type(mpmc_context), value :: ctx
      character(kind=c_char), intent(out) :: buf(*)
      integer(c_int), value :: len
      integer(c_int) :: ierr
    end function
    function mpmc_context_clear_error(ctx) bind(C, name='mpmc_context_clear_error') result(ierr)
      import :: c_int, mpmc_context
      type(mpmc_context), value :: ctx
      integer(c_int) :: ierr
    end function
    function mpmc_context_get_last_code(ctx, code) &
        bind(C, name='mpmc_context_get_last_code') result(ierr)
      import :: c_int, mpmc_context
      type(mpmc_context), value :: ctx
      integer(c_int), intent(out) :: code
      integer(c_int) :: ierr
    end function
    function mpmc_context_set_error_c(ctx, code, file, line, message) &
        bind(C, name='mpmc_context_set_error') result(ierr)
      import :: c_int, c_char, mpmc_context
      type(mpmc_context), value :: ctx
      integer(c_int), value :: code, line
      character(kind=c_char), intent(in) :: file(*), message(*)
      integer(c_int) :: ierr
    end function
    function mpmc_context_set_log_level(ctx, level) &
        bind(C, name='mpmc_context_set_log_level') result(ierr)
      import :: c_int, mpmc_context
      type(mpmc_context), value :: ctx
      integer(c_int), value :: level
      integer(c_int) :: ierr
    end function
    function mpmc_version(major, minor, patch) bind(C, name='mpmc_version') result(ierr)
      import :: c_int
      integer(c_int), intent(out) :: major, minor, patch
      integer(c_int) :: ierr
    end function

    ! ---- simulation set-up ----------------------------------------------------------------
    function mpmc_sim_create(ctx, dim, sim) bind(C, name='mpmc_sim_create') result(ierr)
      import :: c_int, mpmc_context, mpmc_sim
      type(mpmc_context), value :: ctx
      integer(c_int), value :: dim
      type(mpmc_sim), intent(out) :: sim
      integer(c_int) :: ierr
    end function
    function mpmc_sim_destroy(sim) bind(C, name='mpmc_sim_destroy') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), intent(inout) :: sim
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_context(sim, ctx) bind(C, name='mpmc_sim_get_context') result(ierr)
      import :: c_int, mpmc_context, mpmc_sim
      type(mpmc_sim), value :: sim
      type(mpmc_context), intent(out) :: ctx
      integer(c_int) :: ierr
    end function
    function mpmc_sim_create_mpi_f(ctx, comm, dim, sim) bind(C, name='mpmc_sim_create_mpi_f') &
        result(ierr)
      import :: c_int, mpmc_context, mpmc_sim
      type(mpmc_context), value :: ctx
      integer(c_int), value :: comm
      integer(c_int), value :: dim
      type(mpmc_sim), intent(out) :: sim
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_mpi_slab(sim, rank, nranks, axis, cell_lo, cell_hi) &
        bind(C, name='mpmc_sim_get_mpi_slab') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), intent(out) :: rank, nranks, axis, cell_lo, cell_hi
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_mpi_traffic(sim, halo_bytes, halo_msgs, migrated_bytes, &
        migrate_msgs) bind(C, name='mpmc_sim_get_mpi_traffic') result(ierr)
      import :: c_int, c_long, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(out) :: halo_bytes, migrated_bytes
      integer(c_long), intent(out) :: halo_msgs, migrate_msgs
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_mpi_balance(sim, every_n_steps, threshold) &
        bind(C, name='mpmc_sim_set_mpi_balance') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: every_n_steps
      real(c_double), value :: threshold
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_mpi_imbalance(sim, imbalance, balances) &
        bind(C, name='mpmc_sim_get_mpi_imbalance') result(ierr)
      import :: c_int, c_long, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(out) :: imbalance
      integer(c_long), intent(out) :: balances
      integer(c_int) :: ierr
    end function
    ! mpmc_sim_checkpoint_read over the ranks of comm, as the C function (MPI builds only):
    ! path a C string (trim(path)//c_null_char); meta the checkpoint's text (release it with
    ! mpmc_free), or c_null_ptr
    function mpmc_sim_checkpoint_read_mpi_f(ctx, comm, path, sim, meta) &
        bind(C, name='mpmc_sim_checkpoint_read_mpi_f') result(ierr)
      import :: c_int, c_char, c_ptr, mpmc_context, mpmc_sim
      type(mpmc_context), value :: ctx
      integer(c_int), value :: comm
      character(kind=c_char), intent(in) :: path(*)
      type(mpmc_sim), intent(out) :: sim
      type(c_ptr), intent(out) :: meta
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_dim(sim, dim) bind(C, name='mpmc_sim_get_dim') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), intent(out) :: dim
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_grid(sim, lo, hi, h) bind(C, name='mpmc_sim_set_grid') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(in) :: lo(*), hi(*)
      real(c_double), value :: h
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_grid(sim, lo, hi, h) bind(C, name='mpmc_sim_get_grid') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(out) :: lo(*), hi(*)
      real(c_double), intent(out) :: h
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_basis(sim, basis) bind(C, name='mpmc_sim_set_basis') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: basis
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_fbar(sim, mode) bind(C, name='mpmc_sim_set_fbar') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: mode
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_fbar(sim, mode) bind(C, name='mpmc_sim_get_fbar') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), intent(out) :: mode
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_flip_blend(sim, eta) bind(C, name='mpmc_sim_set_flip_blend') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: eta
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_pic_diffusivity(sim, d) bind(C, name='mpmc_sim_set_pic_diffusivity') &
        result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: d
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_gravity(sim, g) bind(C, name='mpmc_sim_set_gravity') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(in) :: g(*)
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_damping(sim, alpha) bind(C, name='mpmc_sim_set_damping') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: alpha
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_kinetic_damping(sim, on) bind(C, name='mpmc_sim_set_kinetic_damping') &
        result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: on
      integer(c_int) :: ierr
    end function
    ! adaptive viscous damping, c = 2 zeta omega (omega estimated each step): zeta in [0, 2],
    ! 1 critical, 0 off
    function mpmc_sim_set_adaptive_damping(sim, zeta) &
        bind(C, name='mpmc_sim_set_adaptive_damping') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: zeta
      integer(c_int) :: ierr
    end function
    ! c [1/s] the next step applies
    function mpmc_sim_get_adaptive_damping(sim, c) &
        bind(C, name='mpmc_sim_get_adaptive_damping') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(out) :: c
      integer(c_int) :: ierr
    end function
    ! xh(2, n): (x, h) of the piezometric line, x increasing; n = 0 removes the table
    function mpmc_sim_set_water_table(sim, n, xh, gamma_w) &
        bind(C, name='mpmc_sim_set_water_table') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: n
      real(c_double), intent(in) :: xh(*)
      real(c_double), value :: gamma_w
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_geostatic_stress(sim, k0) &
        bind(C, name='mpmc_sim_set_geostatic_stress') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: k0
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_water_table_plane(sim, a, b, c, gamma_w) &
        bind(C, name='mpmc_sim_set_water_table_plane') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: a, b, c, gamma_w
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_solver(sim, solver) bind(C, name='mpmc_sim_set_solver') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: solver
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_kernels(sim, kernels) bind(C, name='mpmc_sim_set_kernels') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: kernels
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_kernels(sim, kernels) bind(C, name='mpmc_sim_get_kernels') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), intent(out) :: kernels
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_threads(sim, nthreads) bind(C, name='mpmc_sim_set_threads') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: nthreads
      integer(c_int) :: ierr
    end function
    !> Sort the points by grid cell every nsteps steps (0: never, the default): the arrays
    !> are permuted in place, particle sets renumbered; mpmc_sim_get_particle_ids follows
    !> each point.
    function mpmc_sim_set_sort_interval(sim, nsteps) bind(C, name='mpmc_sim_set_sort_interval') &
        result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: nsteps
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_sort_interval(sim, nsteps) bind(C, name='mpmc_sim_get_sort_interval') &
        result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), intent(out) :: nsteps
      integer(c_int) :: ierr
    end function
    !> Sort the points by grid cell now.
    function mpmc_sim_sort_particles(sim) bind(C, name='mpmc_sim_sort_particles') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int) :: ierr
    end function

    ! ---- materials ------------------------------------------------------------------------
    function mpmc_sim_add_material_neo_hookean(sim, E, nu, rho, id) &
        bind(C, name='mpmc_sim_add_material_neo_hookean') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: E, nu, rho
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_add_material_hencky(sim, E, nu, rho, id) &
        bind(C, name='mpmc_sim_add_material_hencky') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: E, nu, rho
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, kappa_p, kappa_r, eta, id) &
        bind(C, name='mpmc_sim_add_material_hencky_j2') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: E, nu, rho, kappa_p, kappa_r, eta
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    !> Hencky-J2 with undrained shear strengths: kappa = sqrt(3) su.
    function mpmc_sim_add_material_hencky_j2_su(sim, E, nu, rho, su_p, su_r, eta, id) &
        bind(C, name='mpmc_sim_add_material_hencky_j2_su') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: E, nu, rho, su_p, su_r, eta
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_add_material_newtonian(sim, K, mu, rho, id) &
        bind(C, name='mpmc_sim_add_material_newtonian') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: K, mu, rho
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_num_materials(sim, n) bind(C, name='mpmc_sim_get_num_materials') &
        result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), intent(out) :: n
      integer(c_int) :: ierr
    end function
    function mpmc_sim_reduce_strength(sim, material, factor) &
        bind(C, name='mpmc_sim_reduce_strength') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: material
      real(c_double), value :: factor
      integer(c_int) :: ierr
    end function
    !> fn = c_funloc(a procedure with the mpmc_user_stress_fn interface)
    function mpmc_sim_add_material_user(sim, fn, data, nstate, rho, wave_speed, id) &
        bind(C, name='mpmc_sim_add_material_user') result(ierr)
      import :: c_int, c_double, c_ptr, c_funptr, mpmc_sim
      type(mpmc_sim), value :: sim
      type(c_funptr), value :: fn
      type(c_ptr), value :: data
      integer(c_int), value :: nstate
      real(c_double), value :: rho, wave_speed
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    !> After mpmc_sim_checkpoint_read: re-attach the stress function of a user material.
    function mpmc_sim_set_material_user_fn(sim, material, fn, data) &
        bind(C, name='mpmc_sim_set_material_user_fn') result(ierr)
      import :: c_int, c_ptr, c_funptr, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: material
      type(c_funptr), value :: fn
      type(c_ptr), value :: data
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_strength_reduction(sim, material, factor) &
        bind(C, name='mpmc_sim_set_strength_reduction') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: material
      real(c_double), value :: factor
      integer(c_int) :: ierr
    end function
    !> Angles in degrees; residual values NaN (ieee_value) for "the peak value";
    !> sigma_t = huge(1.0_c_double) or +Inf for no tension cut-off beyond the apex.
    function mpmc_sim_add_material_mohr_coulomb(sim, E, nu, rho, c, phi, psi, c_r, phi_r, &
        psi_r, eta, sigma_t, id) bind(C, name='mpmc_sim_add_material_mohr_coulomb') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: E, nu, rho, c, phi, psi, c_r, phi_r, psi_r, eta, sigma_t
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_add_material_drucker_prager(sim, E, nu, rho, c, phi, psi, c_r, phi_r, &
        psi_r, eta, sigma_t, match, id) bind(C, name='mpmc_sim_add_material_drucker_prager') &
        result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: E, nu, rho, c, phi, psi, c_r, phi_r, psi_r, eta, sigma_t
      integer(c_int), value :: match
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    !> fn = c_funloc(a procedure with the mpmc_yield_fn interface)
    function mpmc_sim_add_material_user_yield(sim, fn, data, E, nu, rho, id) &
        bind(C, name='mpmc_sim_add_material_user_yield') result(ierr)
      import :: c_int, c_double, c_ptr, c_funptr, mpmc_sim
      type(mpmc_sim), value :: sim
      type(c_funptr), value :: fn
      type(c_ptr), value :: data
      real(c_double), value :: E, nu, rho
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_material_yield_fn(sim, material, fn, data) &
        bind(C, name='mpmc_sim_set_material_yield_fn') result(ierr)
      import :: c_int, c_ptr, c_funptr, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: material
      type(c_funptr), value :: fn
      type(c_ptr), value :: data
      integer(c_int) :: ierr
    end function
    !> par(1:nstore) of the model (0-based model index); factor: the strength reduction
    function mpmc_sim_get_material(sim, material, model, par, factor) &
        bind(C, name='mpmc_sim_get_material') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: material
      integer(c_int), intent(out) :: model
      real(c_double), intent(out) :: par(*)
      real(c_double), intent(out) :: factor
      integer(c_int) :: ierr
    end function
    function mpmc_model_count(n) bind(C, name='mpmc_model_count') result(ierr)
      import :: c_int
      integer(c_int), intent(out) :: n
      integer(c_int) :: ierr
    end function
    function mpmc_model_find_c(name, model) bind(C, name='mpmc_model_find') result(ierr)
      import :: c_int, c_char
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int), intent(out) :: model
      integer(c_int) :: ierr
    end function
    function mpmc_model_get_info(model, info) bind(C, name='mpmc_model_get_info') result(ierr)
      import :: c_int, mpmc_model_info
      integer(c_int), value :: model
      type(mpmc_model_info), intent(out) :: info
      integer(c_int) :: ierr
    end function
    !> parameter k (0-based) of the model
    function mpmc_model_get_param(model, k, info) bind(C, name='mpmc_model_get_param') &
        result(ierr)
      import :: c_int, mpmc_param_info
      integer(c_int), value :: model, k
      type(mpmc_param_info), intent(out) :: info
      integer(c_int) :: ierr
    end function
    function mpmc_sim_add_material_c(sim, model, par, npar, id) &
        bind(C, name='mpmc_sim_add_material') result(ierr)
      import :: c_int, c_char, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      character(kind=c_char), intent(in) :: model(*)
      real(c_double), intent(in) :: par(*)
      integer(c_int), value :: npar
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_user_state_c(sim, material, state, nstate) &
        bind(C, name='mpmc_sim_get_user_state') result(ierr)
      import :: c_int, c_ptr, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: material
      type(c_ptr), intent(out) :: state
      integer(c_int), intent(out) :: nstate
      integer(c_int) :: ierr
    end function

    ! ---- material points ------------------------------------------------------------------
    !> x(dim, n) positions, volume(n); first receives the 0-based index of the first point.
    function mpmc_sim_add_particles(sim, n, x, volume, material, first) &
        bind(C, name='mpmc_sim_add_particles') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: n
      real(c_double), intent(in) :: x(*), volume(*)
      integer(c_int), value :: material
      integer(c_int), intent(out) :: first
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_num_particles(sim, n) bind(C, name='mpmc_sim_get_num_particles') &
        result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), intent(out) :: n
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_field_c(sim, field, data, ncomp) bind(C, name='mpmc_sim_get_field') &
        result(ierr)
      import :: c_int, c_ptr, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: field
      type(c_ptr), intent(out) :: data
      integer(c_int), intent(out) :: ncomp
      integer(c_int) :: ierr
    end function
    function mpmc_sim_restore_field_c(sim, field, data) bind(C, name='mpmc_sim_restore_field') &
        result(ierr)
      import :: c_int, c_ptr, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: field
      type(c_ptr), intent(inout) :: data
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_material_ids_c(sim, ids) bind(C, name='mpmc_sim_get_material_ids') &
        result(ierr)
      import :: c_int, c_ptr, mpmc_sim
      type(mpmc_sim), value :: sim
      type(c_ptr), intent(out) :: ids
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_particle_ids_c(sim, ids) bind(C, name='mpmc_sim_get_particle_ids') &
        result(ierr)
      import :: c_int, c_ptr, mpmc_sim
      type(mpmc_sim), value :: sim
      type(c_ptr), intent(out) :: ids
      integer(c_int) :: ierr
    end function
    !> f(dim, n): external force on points first .. first+n-1 (0-based).
    function mpmc_sim_set_particle_forces(sim, first, n, f) &
        bind(C, name='mpmc_sim_set_particle_forces') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: first, n
      real(c_double), intent(in) :: f(*)
      integer(c_int) :: ierr
    end function

    ! ---- walls ----------------------------------------------------------------------------
    function mpmc_sim_add_wall(sim, axis, side, position, kind, id) &
        bind(C, name='mpmc_sim_add_wall') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: axis, side
      real(c_double), value :: position
      integer(c_int), value :: kind
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_add_wall_face(sim, face, kind, id) bind(C, name='mpmc_sim_add_wall_face') &
        result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: face, kind
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_add_wall_box(sim, lo, hi, kind, axis, side, id) &
        bind(C, name='mpmc_sim_add_wall_box') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(in) :: lo(*), hi(*)
      integer(c_int), value :: kind, axis, side
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_add_wall_nodes(sim, set, kind, axis, side, id) &
        bind(C, name='mpmc_sim_add_wall_nodes') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: set, kind, axis, side
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_remove_wall(sim, id) bind(C, name='mpmc_sim_remove_wall') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: id
      integer(c_int) :: ierr
    end function

    ! ---- time stepping --------------------------------------------------------------------
    function mpmc_sim_stable_dt(sim, factor, dt) bind(C, name='mpmc_sim_stable_dt') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: factor
      real(c_double), intent(out) :: dt
      integer(c_int) :: ierr
    end function
    function mpmc_sim_step(sim, dt) bind(C, name='mpmc_sim_step') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: dt
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_force_dt(sim, force) bind(C, name='mpmc_sim_set_force_dt') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: force
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_time(sim, t) bind(C, name='mpmc_sim_get_time') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(out) :: t
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_time(sim, t) bind(C, name='mpmc_sim_set_time') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: t
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_kinetic_energy(sim, ke) bind(C, name='mpmc_sim_get_kinetic_energy') &
        result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(out) :: ke
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_stats(sim, stats) bind(C, name='mpmc_sim_get_stats') result(ierr)
      import :: c_int, mpmc_sim, mpmc_stats
      type(mpmc_sim), value :: sim
      type(mpmc_stats), intent(out) :: stats
      integer(c_int) :: ierr
    end function

    ! ---- run monitor ------------------------------------------------------------------------
    !> Stop a step with MPMC_ERR_UNSTABLE when the kinetic energy exceeds factor times the
    !> energy available since the last change of inputs: factor > 1 (default
    !> MPMC_MONITOR_ENERGY_FACTOR), 0 restores the default, < 0 turns the check off.  Every
    !> call starts a new baseline.
    function mpmc_sim_set_energy_monitor(sim, factor) bind(C, name='mpmc_sim_set_energy_monitor') &
        result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: factor
      integer(c_int) :: ierr
    end function

    ! ---- rigid bodies and contact -------------------------------------------------------
    function mpmc_sim_add_rigid_box(sim, lo, hi, mu, id) bind(C, name='mpmc_sim_add_rigid_box') &
        result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(in) :: lo(*), hi(*)
      real(c_double), value :: mu
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    !> 2D only: xy(2, nvert).
    function mpmc_sim_add_rigid_polygon(sim, nvert, xy, mu, id) &
        bind(C, name='mpmc_sim_add_rigid_polygon') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: nvert
      real(c_double), intent(in) :: xy(*)
      real(c_double), value :: mu
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_remove_rigid(sim, id) bind(C, name='mpmc_sim_remove_rigid') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_rigid_velocity(sim, id, v) bind(C, name='mpmc_sim_set_rigid_velocity') &
        result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: id
      real(c_double), intent(in) :: v(*)
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_rigid_offset(sim, id, offset) bind(C, name='mpmc_sim_get_rigid_offset') &
        result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: id
      real(c_double), intent(out) :: offset(*)
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_rigid_reaction(sim, id, f) bind(C, name='mpmc_sim_get_rigid_reaction') &
        result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: id
      real(c_double), intent(out) :: f(*)
      integer(c_int) :: ierr
    end function
    !> point: the 0-based index of the closest point.
    function mpmc_sim_get_rigid_gap(sim, id, gap, point) bind(C, name='mpmc_sim_get_rigid_gap') &
        result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: id
      real(c_double), intent(out) :: gap
      integer(c_int), intent(out) :: point
      integer(c_int) :: ierr
    end function
    function mpmc_sim_set_contact_params(sim, dhat, kappa) &
        bind(C, name='mpmc_sim_set_contact_params') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), value :: dhat, kappa
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_contact_params(sim, dhat, kappa) &
        bind(C, name='mpmc_sim_get_contact_params') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(out) :: dhat, kappa
      integer(c_int) :: ierr
    end function

    ! ---- particle sets --------------------------------------------------------------------
    function mpmc_sim_add_particle_set_c(sim, name, n, idx, id) &
        bind(C, name='mpmc_sim_add_particle_set') result(ierr)
      import :: c_int, c_char, mpmc_sim
      type(mpmc_sim), value :: sim
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int), value :: n
      integer(c_int), intent(in) :: idx(*)
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_num_particle_sets(sim, n) &
        bind(C, name='mpmc_sim_get_num_particle_sets') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), intent(out) :: n
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_particle_set_c(sim, id, name, n, idx) &
        bind(C, name='mpmc_sim_get_particle_set') result(ierr)
      import :: c_int, c_ptr, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: id
      type(c_ptr), intent(out) :: name
      integer(c_int), intent(out) :: n
      type(c_ptr), intent(out) :: idx
      integer(c_int) :: ierr
    end function
    function mpmc_sim_find_particle_set_c(sim, name, id) &
        bind(C, name='mpmc_sim_find_particle_set') result(ierr)
      import :: c_int, c_char, mpmc_sim
      type(mpmc_sim), value :: sim
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function

    ! ---- node sets ------------------------------------------------------------------------
    function mpmc_sim_add_node_set_c(sim, name, n, ijk, id) &
        bind(C, name='mpmc_sim_add_node_set') result(ierr)
      import :: c_int, c_char, mpmc_sim
      type(mpmc_sim), value :: sim
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int), value :: n
      integer(c_int), intent(in) :: ijk(*)
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_num_node_sets(sim, n) &
        bind(C, name='mpmc_sim_get_num_node_sets') result(ierr)
      import :: c_int, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), intent(out) :: n
      integer(c_int) :: ierr
    end function
    function mpmc_sim_get_node_set_c(sim, id, name, n, ijk) &
        bind(C, name='mpmc_sim_get_node_set') result(ierr)
      import :: c_int, c_ptr, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: id
      type(c_ptr), intent(out) :: name
      integer(c_int), intent(out) :: n
      type(c_ptr), intent(out) :: ijk
      integer(c_int) :: ierr
    end function
    function mpmc_sim_find_node_set_c(sim, name, id) &
        bind(C, name='mpmc_sim_find_node_set') result(ierr)
      import :: c_int, c_char, mpmc_sim
      type(mpmc_sim), value :: sim
      character(kind=c_char), intent(in) :: name(*)
      integer(c_int), intent(out) :: id
      integer(c_int) :: ierr
    end function

    ! ---- seeding --------------------------------------------------------------------------
    function mpmc_sim_seed_box(sim, lo, hi, ppc, material, first, count) &
        bind(C, name='mpmc_sim_seed_box') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      real(c_double), intent(in) :: lo(*), hi(*)
      integer(c_int), value :: ppc, material
      integer(c_int), intent(out) :: first, count
      integer(c_int) :: ierr
    end function
    !> xy(2, nvert): the polygon's vertices.
    function mpmc_sim_seed_polygon(sim, nvert, xy, ppc, material, first, count) &
        bind(C, name='mpmc_sim_seed_polygon') result(ierr)
      import :: c_int, c_double, mpmc_sim
      type(mpmc_sim), value :: sim
      integer(c_int), value :: nvert
      real(c_double), intent(in) :: xy(*)
      integer(c_int), value :: ppc, material
      integer(c_int), intent(out) :: first, count
      integer(c_int) :: ierr
    end function
    !> In libmpmc_gmsh (link it yourself; the Fortran library does not load gmsh):
    !> ierr = mpmc_seed_gmsh(sim, mpmc_c_str('slope.geo'), mpmc_c_str('soil'), ...)
    function mpmc_seed_gmsh(sim, file, region, mode, ppc, material, first, count) &
        bind(C, name='mpmc_seed_gmsh') result(ierr)
      import :: c_int, c_char, mpmc_sim
      type(mpmc_sim), value :: sim
      character(kind=c_char), intent(in) :: file(*), region(*)
      integer(c_int), value :: mode, ppc, material
      integer(c_int), intent(out) :: first, count
      integer(c_int) :: ierr
    end function

    ! ---- output, checkpoints ----------------------------------------------------------------
    function mpmc_output_create_c(sim, h5path, xdmfpath, out) bind(C, name='mpmc_output_create') &
        result(ierr)
      import :: c_int, c_char, mpmc_sim, mpmc_output
      type(mpmc_sim), value :: sim
      character(kind=c_char), intent(in) :: h5path(*), xdmfpath(*)
      type(mpmc_output), intent(out) :: out
      integer(c_int) :: ierr
    end function
    function mpmc_output_write(out) bind(C, name='mpmc_output_write') result(ierr)
      import :: c_int, mpmc_output
      type(mpmc_output), value :: out
      integer(c_int) :: ierr
    end function
    function mpmc_output_destroy(out) bind(C, name='mpmc_output_destroy') result(ierr)
      import :: c_int, mpmc_output
      type(mpmc_output), intent(inout) :: out
      integer(c_int) :: ierr
    end function
    function mpmc_sim_checkpoint_write_c(sim, path, meta) &
        bind(C, name='mpmc_sim_checkpoint_write') result(ierr)
      import :: c_int, c_char, c_ptr, mpmc_sim
      type(mpmc_sim), value :: sim
      character(kind=c_char), intent(in) :: path(*)
      type(c_ptr), value :: meta
      integer(c_int) :: ierr
    end function
    function mpmc_sim_checkpoint_read_c(ctx, path, sim, meta) &
        bind(C, name='mpmc_sim_checkpoint_read') result(ierr)
      import :: c_int, c_char, c_ptr, mpmc_context, mpmc_sim
      type(mpmc_context), value :: ctx
      character(kind=c_char), intent(in) :: path(*)
      type(mpmc_sim), intent(out) :: sim
      type(c_ptr), intent(out) :: meta
      integer(c_int) :: ierr
    end function
    subroutine mpmc_free(ptr) bind(C, name='mpmc_free')
      import :: c_ptr
      type(c_ptr), value :: ptr
    end subroutine

    ! ---- libc -------------------------------------------------------------------------------
    function c_strlen(s) bind(C, name='strlen') result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: s
      integer(c_size_t) :: n
    end function
  end interface

#ifdef MPMC_HAVE_WORKFLOW
  interface
    function mpmc_workflow_run_c(ctx, scene, outdir, noverride, overrides, flags) &
        bind(C, name='mpmc_workflow_run') result(ierr)
      import :: c_int, c_char, c_ptr, mpmc_context
      type(mpmc_context), value :: ctx
      character(kind=c_char), intent(in) :: scene(*), outdir(*)
      integer(c_int), value :: noverride
      type(c_ptr), intent(in) :: overrides(*)
      integer(c_int), value :: flags
      integer(c_int) :: ierr
    end function
    function mpmc_workflow_resume_c(ctx, outdir, flags) bind(C, name='mpmc_workflow_resume') &
        result(ierr)
      import :: c_int, c_char, mpmc_context
      type(mpmc_context), value :: ctx
      character(kind=c_char), intent(in) :: outdir(*)
      integer(c_int), value :: flags
      integer(c_int) :: ierr
    end function
    function mpmc_workflow_resume_set_c(ctx, outdir, noverride, overrides, flags) &
        bind(C, name='mpmc_workflow_resume_set') result(ierr)
      import :: c_int, c_char, c_ptr, mpmc_context
      type(mpmc_context), value :: ctx
      character(kind=c_char), intent(in) :: outdir(*)
      integer(c_int), value :: noverride
      type(c_ptr), intent(in) :: overrides(*)
      integer(c_int), value :: flags
      integer(c_int) :: ierr
    end function
  end interface
#endif

contains

  !> A null-terminated copy of trim(s), for C functions that take a string.
  pure function mpmc_c_str(s) result(c)
    character(*), intent(in) :: s
    character(kind=c_char, len=len_trim(s) + 1) :: c
    c = trim(s)//c_null_char
  end function mpmc_c_str

  ! A Fortran copy of the null-terminated C string at p ('' for a null pointer).
  function f_string(p) result(s)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: i, n
    if (.not. c_associated(p)) then
      s = ''
      return
    end if
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate (character(len=n) :: s)
    do i = 1, n
      s(i:i) = chars(i)
    end do
  end function f_string

  !> A C string (a char pointer of mpmc_model_info or mpmc_param_info) as a Fortran string.
  function mpmc_f_string(p) result(s)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: s
    s = f_string(p)
  end function mpmc_f_string

  !> The table index of the model called name (MPMC_ERR_ARG when there is none).
  function mpmc_model_find(name, model) result(ierr)
    character(*), intent(in) :: name
    integer(c_int), intent(out) :: model
    integer(c_int) :: ierr
    ierr = mpmc_model_find_c(mpmc_c_str(name), model)
  end function mpmc_model_find

  !> Add a material of the named model from its parameters par(1:nstore), in the table's
  !> order and units (mpmc_model_get_param); NaN takes an optional parameter's default.
  function mpmc_sim_add_material(sim, model, par, id) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    character(*), intent(in) :: model
    real(c_double), intent(in) :: par(:)
    integer(c_int), intent(out) :: id
    integer(c_int) :: ierr
    ierr = mpmc_sim_add_material_c(sim, mpmc_c_str(model), par, int(size(par), c_int), id)
  end function mpmc_sim_add_material

  ! ---- errors ---------------------------------------------------------------------------

  !> The message of an error code.
  function mpmc_error_string(code) result(s)
    integer(c_int), intent(in) :: code
    character(len=:), allocatable :: s
    s = f_string(mpmc_error_string_c(code))
  end function mpmc_error_string

  !> The name of a step phase (MPMC_PHASE_*), as summary.json keys stats%phase_seconds.
  function mpmc_phase_name(phase) result(s)
    integer(c_int), intent(in) :: phase
    character(len=:), allocatable :: s
    s = f_string(mpmc_phase_name_c(phase))
  end function mpmc_phase_name

  !> The name of a kernel set (MPMC_KERNELS_*), as the environment variable MPMC_KERNELS and
  !> summary.json spell it.
  function mpmc_kernels_name(kernels) result(s)
    integer(c_int), intent(in) :: kernels
    character(len=:), allocatable :: s
    s = f_string(mpmc_kernels_name_c(kernels))
  end function mpmc_kernels_name

  !> Copy the last error message of ctx into msg (allocated to its length).
  function mpmc_context_get_last_error(ctx, msg) result(ierr)
    type(mpmc_context), intent(in) :: ctx
    character(len=:), allocatable, intent(out) :: msg
    integer(c_int) :: ierr
    integer, parameter :: buflen = 4096 ! MPMC_MSG_LEN
    character(kind=c_char) :: buf(buflen)
    integer :: i, n
    ierr = mpmc_context_get_last_error_c(ctx, buf, int(buflen, c_int))
    if (ierr /= MPMC_SUCCESS) then
      msg = ''
      return
    end if
    n = 0
    do while (n < buflen)
      if (buf(n + 1) == c_null_char) exit
      n = n + 1
    end do
    allocate (character(len=n) :: msg)
    do i = 1, n
      msg(i:i) = buf(i)
    end do
  end function mpmc_context_get_last_error

  !> The message of the last failure recorded in ctx ('' when none).
  function mpmc_context_last_error(ctx) result(msg)
    type(mpmc_context), intent(in) :: ctx
    character(len=:), allocatable :: msg
    if (mpmc_context_get_last_error(ctx, msg) /= MPMC_SUCCESS) msg = 'no context'
  end function mpmc_context_last_error

  ! ---- zero-copy arrays -------------------------------------------------------------------
  ! A field pointer stays the field across steps and sorts until points are added (for the
  ! other cases see the module's header); give it back with mpmc_sim_restore_field when done:
  ! on loan, the velocity makes each step's stability limit take a pass over the points.

  function get_field_2d(sim, field, x) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    integer(c_int), intent(in) :: field
    real(c_double), pointer, intent(out) :: x(:, :)
    integer(c_int) :: ierr, ncomp, np
    type(c_ptr) :: p
    nullify (x)
    ierr = mpmc_sim_get_field_c(sim, field, p, ncomp)
    if (ierr /= MPMC_SUCCESS) return
    ierr = mpmc_sim_get_num_particles(sim, np)
    if (ierr /= MPMC_SUCCESS) return
    call c_f_pointer(p, x, [ncomp, np])
  end function get_field_2d

  function get_field_1d(sim, field, x) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    integer(c_int), intent(in) :: field
    real(c_double), pointer, intent(out) :: x(:)
    integer(c_int) :: ierr, ncomp, np
    type(c_ptr) :: p
    nullify (x)
    ierr = mpmc_sim_get_field_c(sim, field, p, ncomp)
    if (ierr /= MPMC_SUCCESS) return
    ierr = mpmc_sim_get_num_particles(sim, np)
    if (ierr /= MPMC_SUCCESS) return
    call c_f_pointer(p, x, [ncomp*np])
  end function get_field_1d

  function restore_field_2d(sim, field, x) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    integer(c_int), intent(in) :: field
    real(c_double), pointer, intent(inout) :: x(:, :)
    integer(c_int) :: ierr
    type(c_ptr) :: p
    p = c_null_ptr
    if (associated(x)) then
      if (size(x) > 0) p = c_loc(x(1, 1))
    end if
    ierr = mpmc_sim_restore_field_c(sim, field, p)
    nullify (x)
  end function restore_field_2d

  function restore_field_1d(sim, field, x) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    integer(c_int), intent(in) :: field
    real(c_double), pointer, intent(inout) :: x(:)
    integer(c_int) :: ierr
    type(c_ptr) :: p
    p = c_null_ptr
    if (associated(x)) then
      if (size(x) > 0) p = c_loc(x(1))
    end if
    ierr = mpmc_sim_restore_field_c(sim, field, p)
    nullify (x)
  end function restore_field_1d

  !> Borrow the material id of each point, ids(np) (0-based ids; read it, do not write).
  function mpmc_sim_get_material_ids(sim, ids) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    integer(c_int), pointer, intent(out) :: ids(:)
    integer(c_int) :: ierr
    type(c_ptr) :: p
    nullify (ids)
    ierr = mpmc_sim_get_material_ids_c(sim, p)
    if (ierr == MPMC_SUCCESS) ierr = point_ints(sim, p, ids)
  end function mpmc_sim_get_material_ids

  !> Borrow the id of each point, ids(np): the 0-based index the point was added with (equal
  !> to its index until a sort by cell moved it; read it, do not write).
  function mpmc_sim_get_particle_ids(sim, ids) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    integer(c_int), pointer, intent(out) :: ids(:)
    integer(c_int) :: ierr
    type(c_ptr) :: p
    nullify (ids)
    ierr = mpmc_sim_get_particle_ids_c(sim, p)
    if (ierr == MPMC_SUCCESS) ierr = point_ints(sim, p, ids)
  end function mpmc_sim_get_particle_ids

  ! a C array of one int per point as ids(np)
  function point_ints(sim, p, ids) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    type(c_ptr), intent(in) :: p
    integer(c_int), pointer, intent(out) :: ids(:)
    integer(c_int) :: ierr, np
    nullify (ids)
    ierr = mpmc_sim_get_num_particles(sim, np)
    if (ierr /= MPMC_SUCCESS) return
    if (c_associated(p)) call c_f_pointer(p, ids, [np])
  end function point_ints

  !> Borrow the user-material state without a copy: state(nstate, np), nstate the row
  !> length (the widest user material's); unassociated when no user material has state.
  function mpmc_sim_get_user_state(sim, material, state) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    integer(c_int), intent(in) :: material
    real(c_double), pointer, intent(out) :: state(:, :)
    integer(c_int) :: ierr, nstate, np
    type(c_ptr) :: p
    nullify (state)
    ierr = mpmc_sim_get_user_state_c(sim, material, p, nstate)
    if (ierr /= MPMC_SUCCESS) return
    ierr = mpmc_sim_get_num_particles(sim, np)
    if (ierr /= MPMC_SUCCESS) return
    if (c_associated(p)) call c_f_pointer(p, state, [nstate, np])
  end function mpmc_sim_get_user_state

  ! ---- particle sets ------------------------------------------------------------------------

  !> Add (or replace) the set `name` with the 0-based point indices idx.
  function mpmc_sim_add_particle_set(sim, name, idx, id) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    character(*), intent(in) :: name
    integer(c_int), intent(in), contiguous :: idx(:)
    integer(c_int), intent(out) :: id
    integer(c_int) :: ierr
    ierr = mpmc_sim_add_particle_set_c(sim, mpmc_c_str(name), int(size(idx), c_int), idx, id)
  end function mpmc_sim_add_particle_set

  !> Set `id`: its name (a copy) and its 0-based indices idx(n) (borrowed, no copy).
  function mpmc_sim_get_particle_set(sim, id, name, idx) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    integer(c_int), intent(in) :: id
    character(len=:), allocatable, intent(out) :: name
    integer(c_int), pointer, intent(out) :: idx(:)
    integer(c_int) :: ierr, n
    type(c_ptr) :: pname, pidx
    nullify (idx)
    name = ''
    ierr = mpmc_sim_get_particle_set_c(sim, id, pname, n, pidx)
    if (ierr /= MPMC_SUCCESS) return
    name = f_string(pname)
    if (c_associated(pidx)) then
      call c_f_pointer(pidx, idx, [n])
    else
      allocate (idx(0)) ! an empty set
    end if
  end function mpmc_sim_get_particle_set

  !> Record an error in the context as the library does (e.g. from a user material's
  !> callback); returns code.
  function mpmc_context_set_error(ctx, code, file, line, message) result(ierr)
    type(mpmc_context), intent(in) :: ctx
    integer(c_int), intent(in) :: code, line
    character(*), intent(in) :: file, message
    integer(c_int) :: ierr
    ierr = mpmc_context_set_error_c(ctx, code, mpmc_c_str(file), line, mpmc_c_str(message))
  end function mpmc_context_set_error

  function mpmc_sim_find_particle_set(sim, name, id) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    character(*), intent(in) :: name
    integer(c_int), intent(out) :: id
    integer(c_int) :: ierr
    ierr = mpmc_sim_find_particle_set_c(sim, mpmc_c_str(name), id)
  end function mpmc_sim_find_particle_set

  ! ---- node sets ----------------------------------------------------------------------------

  !> Add (or replace) the node set `name`: ijk(dim, n) holds the nodes' 0-based integer
  !> coordinates (node (i, j, k) sits at lo + (i, j, k) h).
  function mpmc_sim_add_node_set(sim, name, ijk, id) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    character(*), intent(in) :: name
    integer(c_int), intent(in), contiguous :: ijk(:, :)
    integer(c_int), intent(out) :: id
    integer(c_int) :: ierr
    ierr = mpmc_sim_add_node_set_c(sim, mpmc_c_str(name), int(size(ijk, 2), c_int), ijk, id)
  end function mpmc_sim_add_node_set

  !> Node set `id`: its name (a copy) and its nodes ijk(dim, n) (borrowed, no copy).
  function mpmc_sim_get_node_set(sim, id, name, ijk) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    integer(c_int), intent(in) :: id
    character(len=:), allocatable, intent(out) :: name
    integer(c_int), pointer, intent(out) :: ijk(:, :)
    integer(c_int) :: ierr, n, dim
    type(c_ptr) :: pname, pijk
    nullify (ijk)
    name = ''
    ierr = mpmc_sim_get_dim(sim, dim)
    if (ierr /= MPMC_SUCCESS) return
    ierr = mpmc_sim_get_node_set_c(sim, id, pname, n, pijk)
    if (ierr /= MPMC_SUCCESS) return
    name = f_string(pname)
    if (c_associated(pijk) .and. n > 0) then
      call c_f_pointer(pijk, ijk, [dim, n])
    else
      allocate (ijk(dim, 0)) ! an empty set
    end if
  end function mpmc_sim_get_node_set

  function mpmc_sim_find_node_set(sim, name, id) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    character(*), intent(in) :: name
    integer(c_int), intent(out) :: id
    integer(c_int) :: ierr
    ierr = mpmc_sim_find_node_set_c(sim, mpmc_c_str(name), id)
  end function mpmc_sim_find_node_set

  ! ---- output and checkpoints ------------------------------------------------------------

  function mpmc_output_create(sim, h5path, xdmfpath, out) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    character(*), intent(in) :: h5path, xdmfpath
    type(mpmc_output), intent(out) :: out
    integer(c_int) :: ierr
    ierr = mpmc_output_create_c(sim, mpmc_c_str(h5path), mpmc_c_str(xdmfpath), out)
  end function mpmc_output_create

  !> Write a checkpoint; meta (optional) is the caller's text stored with it.
  function mpmc_sim_checkpoint_write(sim, path, meta) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    character(*), intent(in) :: path
    character(*), intent(in), optional :: meta
    integer(c_int) :: ierr
    character(kind=c_char, len=:), allocatable, target :: cmeta
    if (present(meta)) then
      cmeta = meta//c_null_char
      ierr = mpmc_sim_checkpoint_write_c(sim, mpmc_c_str(path), c_loc(cmeta))
    else
      ierr = mpmc_sim_checkpoint_write_c(sim, mpmc_c_str(path), c_null_ptr)
    end if
  end function mpmc_sim_checkpoint_write

  !> Create a simulation from a checkpoint; meta (optional) receives the caller's text.
  function mpmc_sim_checkpoint_read(ctx, path, sim, meta) result(ierr)
    type(mpmc_context), intent(in) :: ctx
    character(*), intent(in) :: path
    type(mpmc_sim), intent(out) :: sim
    character(len=:), allocatable, intent(out), optional :: meta
    integer(c_int) :: ierr
    type(c_ptr) :: pmeta
    pmeta = c_null_ptr
    ierr = mpmc_sim_checkpoint_read_c(ctx, mpmc_c_str(path), sim, pmeta)
    if (present(meta)) meta = f_string(pmeta)
    if (c_associated(pmeta)) call mpmc_free(pmeta)
  end function mpmc_sim_checkpoint_read

  ! ---- running a stage ------------------------------------------------------------------

  !> Run one stage of an analysis: step until `duration` [s] of simulated time has passed,
  !> or -- when ke_ratio > 0 (a quasi-static stage) -- until the kinetic energy has fallen to
  !> ke_ratio of its largest value in this stage after at least min_time [s] and stayed there
  !> at every check for 5 % of the stage time so far (at least 50 steps), so that the turning
  !> point of a slow swing does not end the stage (duration is then the maximum time; the
  !> energy is checked on steps 1, 11, 21, ... and at the end).
  !> The step is dt [s] when given and > 0, else mpmc_sim_stable_dt(dt_factor) (default 0.3)
  !> refreshed every 10 steps; the last step is shortened to end on `duration`.  This is the
  !> stage loop of the `mpmc` front end (workflows/run.c, run_stage), so a program that builds
  !> the same scene through the API reproduces `mpmc run` with the same thread count
  !> (t641-legacy-slope-f checks that the two loops stay the same).
  !> @param[out] nsteps steps taken (optional)
  !> @param[out] quasi_static .true. when the kinetic-energy criterion ended the stage
  function mpmc_sim_run_stage(sim, duration, dt_factor, dt, ke_ratio, min_time, nsteps, &
                              quasi_static) result(ierr)
    type(mpmc_sim), intent(in) :: sim
    real(c_double), intent(in) :: duration
    real(c_double), intent(in), optional :: dt_factor, dt, ke_ratio, min_time
    integer, intent(out), optional :: nsteps
    logical, intent(out), optional :: quasi_static
    integer(c_int) :: ierr
    real(c_double) :: factor, dt_fixed, ratio_end, t_min, t, step_dt, h, ke, ke_max, ratio, below
    integer :: n
    logical :: qs, at_end
    factor = 0.3_c_double
    if (present(dt_factor)) factor = dt_factor
    dt_fixed = 0
    if (present(dt)) dt_fixed = dt
    ratio_end = 0
    if (present(ke_ratio)) ratio_end = ke_ratio
    t_min = 0
    if (present(min_time)) t_min = min_time
    if (present(nsteps)) nsteps = 0
    if (present(quasi_static)) quasi_static = .false.
    ierr = MPMC_ERR_ARG
    if (.not. duration > 0) return ! also NaN
    step_dt = dt_fixed
    t = 0
    n = 0
    ke_max = 0
    below = -1
    qs = .false.
    at_end = .false.
    do while (.not. (qs .or. at_end))
      if (dt_fixed <= 0 .and. mod(n, 10) == 0) then
        ierr = mpmc_sim_stable_dt(sim, factor, step_dt)
        if (ierr /= MPMC_SUCCESS) return
      end if
      h = step_dt
      if (t + h > duration) h = duration - t ! land on the stage's end
      ierr = mpmc_sim_step(sim, h)
      if (ierr /= MPMC_SUCCESS) return
      t = t + h
      n = n + 1
      if (present(nsteps)) nsteps = n
      at_end = t >= duration*(1 - 1.0e-9_c_double) ! no sliver of a step for round-off
      if (ratio_end > 0 .and. (mod(n, 10) == 1 .or. at_end)) then
        ierr = mpmc_sim_get_kinetic_energy(sim, ke)
        if (ierr /= MPMC_SUCCESS) return
        ke_max = max(ke_max, ke)
        ratio = 0
        if (ke_max > 0) ratio = ke/ke_max
        if (ratio <= ratio_end .and. t >= t_min) then
          if (below < 0) below = t
          qs = t - below >= max(0.05_c_double*t, 50*h)
        else
          below = -1
        end if
      end if
    end do
    if (present(quasi_static)) quasi_static = qs
    ierr = MPMC_SUCCESS
  end function mpmc_sim_run_stage

  ! ---- the staged workflow -------------------------------------------------------------

  !> Run a YAML scene as `mpmc run scene --out outdir --set ...`; overrides are
  !> "key.path=value" strings (trailing blanks ignored); flags = MPMC_WORKFLOW_FORCE to write
  !> over outdir (MPMC_WORKFLOW_QUIET: no log, MPMC_WORKFLOW_CHECK: validate only).
  !> MPMC_ERR_UNSUPPORTED when libmpmc was built without the workflow library.
  function mpmc_workflow_run(ctx, scene, outdir, overrides, flags) result(ierr)
    type(mpmc_context), intent(in) :: ctx
    character(*), intent(in) :: scene, outdir
    character(*), intent(in), optional :: overrides(:)
    integer(c_int), intent(in), optional :: flags
    integer(c_int) :: ierr
#ifdef MPMC_HAVE_WORKFLOW
    character(kind=c_char), allocatable, target :: buf(:, :)
    type(c_ptr), allocatable :: ptrs(:)
    integer :: n
    integer(c_int) :: f
    f = 0
    if (present(flags)) f = flags
    call c_strings(overrides, buf, ptrs, n)
    ierr = mpmc_workflow_run_c(ctx, mpmc_c_str(scene), mpmc_c_str(outdir), int(n, c_int), ptrs, f)
#else
    ! Built without the workflow library (workflows/): there is nothing to run the scene.
    ierr = MPMC_ERR_UNSUPPORTED
    if (present(overrides) .and. present(flags) .and. len(scene) + len(outdir) < 0 &
        .and. c_associated(ctx%ptr)) ierr = MPMC_ERR_ARG ! (never: uses the arguments)
#endif
  end function mpmc_workflow_run

  !> Continue the run in outdir from its last checkpoint (`mpmc resume`), a finished run once
  !> its scene asks for more; overrides ("key.path=value") apply after the run's own, e.g.
  !> 'stages.runout.end.time=8'; flags: MPMC_WORKFLOW_QUIET.  MPMC_ERR_UNSUPPORTED without
  !> the workflow library.  Calls mpmc_workflow_resume without overrides and
  !> mpmc_workflow_resume_set with them.
  function mpmc_workflow_resume(ctx, outdir, flags, overrides) result(ierr)
    type(mpmc_context), intent(in) :: ctx
    character(*), intent(in) :: outdir
    integer(c_int), intent(in), optional :: flags
    character(*), intent(in), optional :: overrides(:)
    integer(c_int) :: ierr
#ifdef MPMC_HAVE_WORKFLOW
    character(kind=c_char), allocatable, target :: buf(:, :)
    type(c_ptr), allocatable :: ptrs(:)
    integer :: n
    integer(c_int) :: f
    f = 0
    if (present(flags)) f = flags
    if (.not. present(overrides)) then
      ierr = mpmc_workflow_resume_c(ctx, mpmc_c_str(outdir), f)
      return
    end if
    call c_strings(overrides, buf, ptrs, n)
    ierr = mpmc_workflow_resume_set_c(ctx, mpmc_c_str(outdir), int(n, c_int), ptrs, f)
#else
    ierr = MPMC_ERR_UNSUPPORTED
    if (present(flags) .and. present(overrides) .and. len(outdir) < 0 .and. c_associated(ctx%ptr)) &
      ierr = MPMC_ERR_ARG
#endif
  end function mpmc_workflow_resume

#ifdef MPMC_HAVE_WORKFLOW
  ! NUL-terminated copies of the strings (trailing blanks dropped) in buf and their addresses
  ! in ptrs, n of them (none when absent)
  subroutine c_strings(strings, buf, ptrs, n)
    character(*), intent(in), optional :: strings(:)
    character(kind=c_char), allocatable, target, intent(out) :: buf(:, :)
    type(c_ptr), allocatable, intent(out) :: ptrs(:)
    integer, intent(out) :: n
    integer :: i, j, l
    n = 0
    if (present(strings)) n = size(strings)
    l = 1
    if (n > 0) l = len(strings) + 1
    allocate (buf(l, max(n, 1)), ptrs(max(n, 1)))
    buf = c_null_char
    ptrs = c_null_ptr
    do i = 1, n
      do j = 1, len_trim(strings(i))
        buf(j, i) = strings(i)(j:j)
      end do
      ptrs(i) = c_loc(buf(1, i))
    end do
  end subroutine c_strings
#endif

end module mpmc
