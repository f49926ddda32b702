! legacy_slope: a plain Fortran program that runs the 2D slope analysis through the libmpmc
! API -- gravity initialisation, strength reduction by 1.65, run-out -- and prints the
! run-out distance.  It builds the scene of workflows/slope_2d.yaml call by call (grid,
! material, polygon, walls, stages, time step, end conditions) and runs each stage with
! mpmc_sim_run_stage, the front end's stage loop, so it reproduces
! `mpmc run workflows/slope_2d.yaml` to round-off when both use the same thread count.
!
!   legacy_slope [key=value ...]
!
! The keys are those of `mpmc run --set` that a smaller or faster run needs:
!   threads, sort_interval, grid.cell_size, fbar, stages.gravity.end.kinetic_energy_ratio,
!   stages.gravity.end.max_time, stages.gravity.end.min_time,
!   stages.strength_reduction.end.time, stages.runout.end.time, metrics.runout_distance.toe
! Run-out distance (docs/workflows.md): max(0, max_p x_p - x_toe) with x_toe = 14.95 m.
program legacy_slope
  use, intrinsic :: iso_c_binding, only: c_int, c_double
  use mpmc
  implicit none

  ! ---- the scene: workflows/slope_2d.yaml ---------------------------------------------
  real(c_double), parameter :: grid_lo(2) = [0.0_c_double, 0.0_c_double]
  real(c_double), parameter :: grid_hi(2) = [55.0_c_double, 6.0_c_double]
  real(c_double) :: cell = 0.25_c_double                            ! m
  integer(c_int), parameter :: basis = MPMC_BASIS_UGIMP
  integer(c_int) :: fbar = MPMC_FBAR_ANCHORED                      ! scene: fbar: true
  real(c_double), parameter :: flip = 0.99_c_double                 ! FLIP/PIC blend (eq 13)
  ! sensitive clay (paper section 4.4), Hencky-J2 with exponential softening
  real(c_double), parameter :: E = 25.0e6_c_double, nu = 0.49_c_double, rho = 2150.0_c_double
  real(c_double), parameter :: kappa_p = 40.82e3_c_double, kappa_r = 2.45e3_c_double
  real(c_double), parameter :: eta = 5.0_c_double
  ! cross-section: 5 m high, 45-degree face, crest plateau 9.95 m, toe at x = 14.95 m
  real(c_double), parameter :: slope(2, 4) = reshape([0.0_c_double, 0.0_c_double, &
    14.95_c_double, 0.0_c_double, 9.95_c_double, 5.0_c_double, 0.0_c_double, 5.0_c_double], [2, 4])
  integer(c_int), parameter :: ppc = 2
  real(c_double), parameter :: gravity(2) = [0.0_c_double, -9.81_c_double]
  real(c_double), parameter :: dt_factor = 0.3_c_double            ! the front end's default
  ! stage 1, gravity: strengths doubled (divided by 0.5) so that the slope stands while the
  ! stresses build up; damped until E_k/E_k,max < 1e-3 (after min_time, at most max_time)
  real(c_double), parameter :: gravity_damping = 0.3_c_double, gravity_strength = 0.5_c_double
  real(c_double) :: gravity_ke_ratio = 1.0e-3_c_double
  real(c_double) :: gravity_max_time = 3.0_c_double, gravity_min_time = 0.5_c_double
  ! stage 2, strength_reduction: kappa_p and kappa_r divided by 1.65 (the material's values:
  ! the factor in force is 0.5, so divide by 1.65/0.5), undamped
  real(c_double), parameter :: reduction = 1.65_c_double
  real(c_double) :: reduction_time = 0.5_c_double
  ! stage 3, runout
  real(c_double) :: runout_time = 5.0_c_double
  real(c_double) :: toe = 14.95_c_double
  integer(c_int) :: threads = 1 ! as the scene (threads: 1)
  integer(c_int) :: sort_every = 100 ! steps between sorts of the points by cell, as `mpmc`

  type(mpmc_context) :: ctx
  type(mpmc_sim) :: sim
  integer(c_int) :: mat, first, count, wall
  integer :: nsteps, q, i
  logical :: qs
  real(c_double) :: runout, t
  real(c_double), pointer :: x(:, :)
  character(len=256) :: arg

  do i = 1, command_argument_count()
    call get_command_argument(i, arg)
    call set_option(trim(arg))
  end do

  call check(mpmc_context_create(ctx), 'creating the context')
  call check(mpmc_sim_create(ctx, 2_c_int, sim), 'creating the simulation')
  call check(mpmc_sim_set_grid(sim, grid_lo, grid_hi, cell), 'grid')
  call check(mpmc_sim_set_basis(sim, basis), 'basis')
  call check(mpmc_sim_set_fbar(sim, fbar), 'fbar')
  call check(mpmc_sim_set_flip_blend(sim, flip), 'flip')
  call check(mpmc_sim_set_solver(sim, MPMC_SOLVER_AUTO), 'solver')
  call check(mpmc_sim_set_threads(sim, threads), 'threads')
  call check(mpmc_sim_set_sort_interval(sim, sort_every), 'sort_interval')
  call check(mpmc_sim_add_material_hencky_j2(sim, E, nu, rho, kappa_p, kappa_r, eta, mat), &
    'materials.clay')
  call check(mpmc_sim_seed_polygon(sim, 4_c_int, slope, ppc, mat, first, count), 'geometry')
  write (*, '(a,i0,a)') 'legacy_slope: ', count, ' material points'

  ! stage 1: gravity initialisation; roller behind the slope, fully fixed base
  call check(mpmc_sim_set_gravity(sim, gravity), 'gravity')
  call check(mpmc_sim_set_damping(sim, gravity_damping), 'damping')
  call check(mpmc_sim_add_wall_face(sim, 0_c_int, MPMC_WALL_SLIP, wall), 'wall back (x_lo)')
  call check(mpmc_sim_add_wall_face(sim, 2_c_int, MPMC_WALL_FIXED, wall), 'wall base (y_lo)')
  call check(mpmc_sim_reduce_strength(sim, -1_c_int, gravity_strength), 'gravity strength')
  call check(mpmc_sim_run_stage(sim, gravity_max_time, dt_factor=dt_factor, &
    ke_ratio=gravity_ke_ratio, min_time=gravity_min_time, nsteps=nsteps, quasi_static=qs), &
    'stage gravity')
  call report('gravity')

  ! stage 2: strength reduction by 1.65 (peak and residual strengths), undamped
  call check(mpmc_sim_reduce_strength(sim, -1_c_int, reduction/gravity_strength), &
    'strength reduction')
  call check(mpmc_sim_set_damping(sim, 0.0_c_double), 'damping')
  call check(mpmc_sim_run_stage(sim, reduction_time, dt_factor=dt_factor, nsteps=nsteps), &
    'stage strength_reduction')
  qs = .false.
  call report('strength_reduction')

  ! stage 3: run-out
  call check(mpmc_sim_run_stage(sim, runout_time, dt_factor=dt_factor, nsteps=nsteps), &
    'stage runout')
  call report('runout')

  ! the farthest material beyond the initial toe
  call check(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, x), 'positions')
  runout = 0
  do q = 1, size(x, 2)
    runout = max(runout, x(1, q) - toe)
  end do
  call check(mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, x), 'positions')
  write (*, '(a,es24.16,a)') 'runout_distance = ', runout, ' m'

  call check(mpmc_sim_destroy(sim), 'destroying the simulation')
  call check(mpmc_context_destroy(ctx), 'destroying the context')

contains

  subroutine report(stage)
    character(*), intent(in) :: stage
    call check(mpmc_sim_get_time(sim, t), 'time')
    write (*, '(a,a,a,i0,a,es24.16,a,l1)') 'stage ', stage, ': steps ', nsteps, ', t = ', t, &
      ' s, quasi-static ', qs
  end subroutine report

  ! One `--set`-style override, key=value.
  subroutine set_option(kv)
    character(*), intent(in) :: kv
    integer :: eq, ios
    character(len=:), allocatable :: key, val
    eq = index(kv, '=')
    if (eq < 2) call usage('expected key=value, got "'//kv//'"')
    key = kv(1:eq - 1)
    val = kv(eq + 1:)
    ios = 0
    select case (key)
    case ('threads')
      read (val, *, iostat=ios) threads
    case ('sort_interval')
      read (val, *, iostat=ios) sort_every
    case ('grid.cell_size')
      read (val, *, iostat=ios) cell
    case ('fbar')
      fbar = -1
      if (val == 'true' .or. val == 'anchored') fbar = MPMC_FBAR_ANCHORED
      if (val == 'paper') fbar = MPMC_FBAR_PAPER
      if (val == 'total') fbar = MPMC_FBAR_TOTAL
      if (val == 'stable') fbar = MPMC_FBAR_STABLE
      if (val == 'false') fbar = MPMC_FBAR_OFF
      if (fbar < 0) ios = 1
    case ('stages.gravity.end.max_time')
      read (val, *, iostat=ios) gravity_max_time
    case ('stages.gravity.end.kinetic_energy_ratio')
      read (val, *, iostat=ios) gravity_ke_ratio
    case ('stages.gravity.end.min_time')
      read (val, *, iostat=ios) gravity_min_time
    case ('stages.strength_reduction.end.time')
      read (val, *, iostat=ios) reduction_time
    case ('stages.runout.end.time')
      read (val, *, iostat=ios) runout_time
    case ('metrics.runout_distance.toe')
      read (val, *, iostat=ios) toe
    case default
      call usage('unknown key "'//key//'"')
    end select
    if (ios /= 0) call usage('key "'//key//'": cannot read the value "'//val//'"')
  end subroutine set_option

  subroutine usage(msg)
    character(*), intent(in) :: msg
    write (*, '(a,a)') 'legacy_slope: ', msg
    write (*, '(a)') 'usage: legacy_slope [key=value ...] with keys threads, sort_interval, grid.cell_size, fbar,', &
      '  stages.gravity.end.kinetic_energy_ratio, stages.gravity.end.max_time,', &
      '  stages.gravity.end.min_time,', &
      '  stages.strength_reduction.end.time, stages.runout.end.time, metrics.runout_distance.toe'
    error stop 2
  end subroutine usage

  ! Stop with the library's message when a call fails (a legacy program's error handling).
  subroutine check(ierr, what)
    integer(c_int), intent(in) :: ierr
    character(*), intent(in) :: what
    if (ierr /= MPMC_SUCCESS) then
      write (*, '(a,a,a,i0,a,a)') 'legacy_slope: ', what, ' failed (', ierr, '): ', &
        mpmc_context_last_error(ctx)
      error stop 1
    end if
  end subroutine check

end program legacy_slope
