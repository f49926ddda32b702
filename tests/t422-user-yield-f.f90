! A user yield surface written in Fortran (a bind(C) mpmc_yield_fn registered with c_funloc)
! runs inside the C time step on 2 OpenMP threads: von Mises J2 with exponential softening as
! a user surface gives the built-in mpmc_sim_add_material_hencky_j2's stresses, eps_p and
! positions to 1e-10 in a short 2D slope run (gravity, then a strength reduction that makes
! most of the slope yield), with and without F-bar, checked after every step.  The same
! surface with a wrong derivative (df/dtau with the wrong sign) stops the step with
! MPMC_ERR_SOLVER and a message that says the return did not converge and names df/dtau: it
! never gives a silent wrong stress.
!
! Why no damping: local damping takes sign(v) at every node (damping.c), and nodes that
! should be at rest carry +-1e-20 m/s of round-off; the two materials' round-off differs (the
! built-in takes the Hencky strain by a series, the user path by an eigen-decomposition), so
! a damped gravity stage flips signs and the runs part by 1e-4 within three steps.  Undamped,
! they stay 1e-11 apart (measured, see compare).
module t422_yield
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr, c_f_pointer
  use mpmc, only: mpmc_yield_eval
  implicit none
  private
  public :: j2_params, j2_yield

  !> The surface's constants, handed to the callback through its data pointer.  factor: the
  !> strength reduction (kappa / factor, as mpmc_sim_set_strength_reduction does for the
  !> built-in); fault = 1 flips the sign of df/dtau.
  type, bind(C) :: j2_params
    real(c_double) :: kappa_p, kappa_r, eta, factor
    integer(c_int) :: fault
  end type j2_params

contains

  !> f = sqrt(3/2)|dev tau| - kappa(alpha), kappa(a) = (kappa_r + (kappa_p - kappa_r)
  !> exp(-eta a)) / factor; associated flow r = df/dtau = sqrt(3/2) n, n = s/|s|;
  !> dr/dtau = sqrt(3/2) (P_dev - n n)/|s| with the symmetric identity's shear entries 1/2
  !> (tensor components, mpmc.h).  |s| = 0 (hydrostatic, e.g. the unloaded start) is inside
  !> the surface: the derivatives are set to 0 there, finite as the library asks.
  !> recursive, no SAVE: several threads call it at once.
  recursive function j2_yield(data, tau, alpha, out) bind(C) result(ierr)
    type(c_ptr), value :: data
    real(c_double), intent(in) :: tau(6)
    real(c_double), value :: alpha
    type(mpmc_yield_eval), intent(out) :: out
    integer(c_int) :: ierr
    type(j2_params), pointer :: prm
    real(c_double) :: s(6), n(6), p, ns, e, c, v
    integer :: i, j
    call c_f_pointer(data, prm)
    c = sqrt(1.5_c_double)
    p = (tau(1) + tau(2) + tau(3))/3
    s = tau
    s(1:3) = s(1:3) - p
    ns = sqrt(s(1)**2 + s(2)**2 + s(3)**2 + 2*(s(4)**2 + s(5)**2 + s(6)**2))
    e = (prm%kappa_p - prm%kappa_r)*exp(-prm%eta*alpha)/prm%factor
    out%f = c*ns - (prm%kappa_r/prm%factor + e)
    out%dfdalpha = prm%eta*e
    out%drdalpha = 0
    if (ns > 0) then
      n = s/ns
    else
      n = 0
    end if
    out%r = c*n
    out%dfdtau = c*n
    out%drdtau = 0
    if (ns > 0) then
      do i = 1, 6
        do j = 1, 6
          v = 0
          if (i == j) v = merge(1.0_c_double, 0.5_c_double, i <= 3)
          if (i <= 3 .and. j <= 3) v = v - 1.0_c_double/3
          out%drdtau(j, i) = c*(v - n(i)*n(j))/ns ! d r_i / d tau_j
        end do
      end do
    end if
    if (prm%fault == 1) out%dfdtau = -out%dfdtau
    ierr = 0
  end function j2_yield

end module t422_yield

program t422_user_yield_f
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_loc, c_funloc
  use mpmc
  use t422_yield
  implicit none
  ! slope_2d.yaml's sensitive clay
  real(c_double), parameter :: E = 25.0e6_c_double, nu = 0.49_c_double, &
    rho = 2150.0_c_double, kappa_p = 40.82e3_c_double, kappa_r = 2.45e3_c_double, &
    eta = 5.0_c_double
  ! gravity with the strengths doubled (as slope_2d's first stage: no point yields), then
  ! the paper's reduction by 1.65: about 700 of the 990 points yield within 200 steps
  real(c_double), parameter :: factor_gravity = 0.5_c_double, factor_failure = 1.65_c_double
  integer, parameter :: nsteps_gravity = 200, nsteps_failure = 200
  type(j2_params), target :: prm
  integer :: nfail

  nfail = 0
  call compare(int(MPMC_FBAR_OFF))
  call compare(int(MPMC_FBAR_ANCHORED))
  call wrong_derivative()
  if (nfail > 0) error stop 1

contains

  ! slope_2d.yaml's section (height 5 m, 45-degree face, toe at x = 14.95 m) on 0.5 m cells,
  ! uGIMP, 2 points per cell per axis; slip wall behind, fixed base
  subroutine slope(s, ctx, fbar, user, mat)
    type(mpmc_sim), intent(out) :: s
    type(mpmc_context), intent(in) :: ctx
    integer, intent(in) :: fbar
    logical, intent(in) :: user
    integer(c_int), intent(out) :: mat
    integer(c_int) :: first, count, wall
    call ok(mpmc_sim_create(ctx, 2_c_int, s), 'sim')
    call ok(mpmc_sim_set_grid(s, [0.0_c_double, 0.0_c_double], [25.0_c_double, 6.0_c_double], &
      0.5_c_double), 'grid')
    call ok(mpmc_sim_set_basis(s, MPMC_BASIS_UGIMP), 'basis')
    call ok(mpmc_sim_set_fbar(s, int(fbar, c_int)), 'fbar')
    call ok(mpmc_sim_set_threads(s, 2_c_int), 'threads')
    call ok(mpmc_sim_set_force_dt(s, 1_c_int), 'force dt')
    if (user) then
      call ok(mpmc_sim_add_material_user_yield(s, c_funloc(j2_yield), c_loc(prm), E, nu, rho, &
        mat), 'user yield surface')
    else
      call ok(mpmc_sim_add_material_hencky_j2(s, E, nu, rho, kappa_p, kappa_r, eta, mat), &
        'built-in hencky_j2')
    end if
    call ok(mpmc_sim_seed_polygon(s, 4_c_int, [0.0_c_double, 0.0_c_double, 14.95_c_double, &
      0.0_c_double, 9.95_c_double, 5.0_c_double, 0.0_c_double, 5.0_c_double], 2_c_int, mat, &
      first, count), 'seed')
    call ok(mpmc_sim_add_wall_face(s, 0_c_int, MPMC_WALL_SLIP, wall), 'back wall')
    call ok(mpmc_sim_add_wall_face(s, 2_c_int, MPMC_WALL_FIXED, wall), 'base')
    call ok(mpmc_sim_set_gravity(s, [0.0_c_double, -9.81_c_double]), 'gravity')
  end subroutine slope

  ! The strength reduction of both: the built-in's through the library, the user surface's
  ! through its data.
  subroutine reduce(s, mat, factor)
    type(mpmc_sim), intent(in) :: s(2)
    integer(c_int), intent(in) :: mat(2)
    real(c_double), intent(in) :: factor
    call ok(mpmc_sim_set_strength_reduction(s(1), mat(1), factor), 'strength reduction')
    prm%factor = factor
  end subroutine reduce

  ! The same slope twice, with the built-in J2 and with the Fortran surface, the same fixed
  ! step: stresses, eps_p and positions point by point after every step.  The stress scale is
  ! the largest |stress| of the built-in run so far, and at least the geostatic stress at the
  ! base, rho g H = 1.05e5 Pa: undamped, the slope rings after gravity comes on and the
  ! largest stress swings between 0.5 and 2.7e5 Pa, while the difference only grows (the two
  ! Hencky strains' round-off, ~1e-16 of b a step, times 1/strain: 1.4e-7 Pa after two
  ! steps, when the largest stress is 2.3e3 Pa; 6.6e-6 Pa after 400).  Measured: at most
  ! 2.0e-11 (F-bar off) and 3.4e-11 (anchored) of that scale (eps_p: 9e-13, 3.7e-11);
  ! 734 and 700 plastic points, 75,000 return maps each.
  subroutine compare(fbar)
    integer, intent(in) :: fbar
    type(mpmc_context) :: ctx
    type(mpmc_sim) :: s(2)
    type(mpmc_stats) :: st(2)
    integer(c_int) :: mat(2), n(2)
    real(c_double) :: dt, smax, err, eerr, xerr
    integer :: k, step, nplastic, nfail0
    character(len=32) :: label

    write (label, '(a,i0)') 'fbar ', fbar
    nfail0 = nfail
    prm = j2_params(kappa_p, kappa_r, eta, 1.0_c_double, 0_c_int)
    call ok(mpmc_context_create(ctx), 'context')
    call slope(s(1), ctx, fbar, .false., mat(1))
    call slope(s(2), ctx, fbar, .true., mat(2))
    call ok(mpmc_sim_get_num_particles(s(1), n(1)), 'points 1')
    call ok(mpmc_sim_get_num_particles(s(2), n(2)), 'points 2')
    if (nfail > nfail0 .or. n(1) /= n(2)) then
      write (*, '(3a,i0,a,i0)') 'FAILED: ', trim(label), ': set-up, points ', n(1), ' and ', n(2)
      nfail = nfail + 1
      return
    end if
    ! a fixed step for both: the built-in's stable step at rest (0.3 h / c), kept
    call ok(mpmc_sim_stable_dt(s(1), 0.3_c_double, dt), 'stable dt')
    call reduce(s, mat, factor_gravity)
    smax = rho*9.81_c_double*5 ! rho g H
    err = 0
    eerr = 0
    xerr = 0
    do step = 1, nsteps_gravity + nsteps_failure
      if (step == nsteps_gravity + 1) call reduce(s, mat, factor_failure)
      do k = 1, 2
        call ok(mpmc_sim_step(s(k), dt), 'step')
      end do
      if (nfail > nfail0) then
        write (*, '(3a,i0,2a)') 'FAILED: ', trim(label), ': step ', step, ': ', &
          mpmc_context_last_error(ctx)
        return
      end if
      call differences(s, smax, err, eerr, xerr, nplastic)
      if (nfail > nfail0) return
    end do
    call ok(mpmc_sim_get_stats(s(1), st(1)), 'stats 1')
    call ok(mpmc_sim_get_stats(s(2), st(2)), 'stats 2')
    if (getenv_set('T422_VERBOSE')) &
      write (*, '(3a,es10.3,a,es10.3,a,es10.3,a,es10.3,a,i0,a,i0,2(a,i0))') 'compare ', &
        trim(label), ': stress ', err, ' eps_p ', eerr, ' x ', xerr, ' m; stress scale ', smax, &
        ' Pa; plastic ', nplastic, ' of ', n(1), '; return maps ', st(1)%return_maps, ' / ', &
        st(2)%return_maps
    if (.not. (nplastic > 0 .and. st(1)%return_maps > 0 .and. st(2)%return_maps > 0)) then
      write (*, '(3a,i0,a,i0,a,i0,a)') 'FAILED: ', trim(label), &
        ': expected plastic points, got ', nplastic, ' (return maps ', st(1)%return_maps, &
        ' built-in, ', st(2)%return_maps, ' user)'
      nfail = nfail + 1
    end if
    if (.not. err <= 1.0e-10_c_double) then
      write (*, '(4a,es12.4)') 'FAILED: ', trim(label), ': user J2 stress vs built-in: ', &
        'expected max |difference| / stress scale <= 1e-10, got ', err
      nfail = nfail + 1
    end if
    if (.not. eerr <= 1.0e-10_c_double) then
      write (*, '(4a,es12.4)') 'FAILED: ', trim(label), ': user J2 eps_p vs built-in: ', &
        'expected 2G max |difference| / stress scale <= 1e-10, got ', eerr
      nfail = nfail + 1
    end if
    if (.not. xerr <= 1.0e-10_c_double) then
      write (*, '(3a,es12.4)') 'FAILED: ', trim(label), &
        ': positions: expected difference <= 1e-10 m, got ', xerr
      nfail = nfail + 1
    end if
    do k = 1, 2
      call ok(mpmc_sim_destroy(s(k)), 'destroy')
    end do
    call ok(mpmc_context_destroy(ctx), 'destroy context')
  end subroutine compare

  ! The largest differences so far: stress over the stress scale so far, eps_p in stress
  ! units (2G eps_p, as t415 compares it) over the same, positions in metres.
  subroutine differences(s, smax, err, eerr, xerr, nplastic)
    type(mpmc_sim), intent(in) :: s(2)
    real(c_double), intent(inout) :: smax, err, eerr, xerr
    integer, intent(out) :: nplastic
    real(c_double), pointer :: s1(:, :), s2(:, :), e1(:, :), e2(:, :), x1(:, :), x2(:, :)
    nplastic = 0
    call ok(mpmc_sim_get_field(s(1), MPMC_FIELD_STRESS, s1), 'stress 1')
    call ok(mpmc_sim_get_field(s(2), MPMC_FIELD_STRESS, s2), 'stress 2')
    call ok(mpmc_sim_get_field(s(1), MPMC_FIELD_EPS_P, e1), 'eps_p 1')
    call ok(mpmc_sim_get_field(s(2), MPMC_FIELD_EPS_P, e2), 'eps_p 2')
    call ok(mpmc_sim_get_field(s(1), MPMC_FIELD_POSITION, x1), 'x 1')
    call ok(mpmc_sim_get_field(s(2), MPMC_FIELD_POSITION, x2), 'x 2')
    if (.not. (associated(s1) .and. associated(s2) .and. associated(e1) .and. &
               associated(e2) .and. associated(x1) .and. associated(x2))) return
    smax = max(smax, maxval(abs(s1)))
    err = max(err, maxval(abs(s2 - s1))/smax)
    eerr = max(eerr, E/(1 + nu)*maxval(abs(e2 - e1))/smax)
    xerr = max(xerr, maxval(abs(x2 - x1)))
    nplastic = count(e1(1, :) > 0)
    call ok(mpmc_sim_restore_field(s(1), MPMC_FIELD_STRESS, s1), 'restore')
    call ok(mpmc_sim_restore_field(s(2), MPMC_FIELD_STRESS, s2), 'restore')
    call ok(mpmc_sim_restore_field(s(1), MPMC_FIELD_EPS_P, e1), 'restore')
    call ok(mpmc_sim_restore_field(s(2), MPMC_FIELD_EPS_P, e2), 'restore')
    call ok(mpmc_sim_restore_field(s(1), MPMC_FIELD_POSITION, x1), 'restore')
    call ok(mpmc_sim_restore_field(s(2), MPMC_FIELD_POSITION, x2), 'restore')
  end subroutine differences

  ! df/dtau with the wrong sign, on the slope with the strengths reduced by 1.65 from the
  ! start: the first plastic point (the toe, step 59) stops the step with MPMC_ERR_SOLVER and
  ! a message naming the non-convergence and the derivative.
  subroutine wrong_derivative()
    type(mpmc_context) :: ctx
    type(mpmc_sim) :: s
    integer(c_int) :: mat, ierr
    real(c_double) :: dt
    character(len=:), allocatable :: msg
    integer :: step
    prm = j2_params(kappa_p, kappa_r, eta, factor_failure, 1_c_int)
    call ok(mpmc_context_create(ctx), 'context')
    call ok(mpmc_context_set_log_level(ctx, MPMC_LOG_SILENT), 'log level')
    call slope(s, ctx, int(MPMC_FBAR_ANCHORED), .true., mat)
    call ok(mpmc_sim_stable_dt(s, 0.3_c_double, dt), 'stable dt')
    if (nfail > 0) return
    ierr = MPMC_SUCCESS
    do step = 1, nsteps_gravity + nsteps_failure
      ierr = mpmc_sim_step(s, dt)
      if (ierr /= MPMC_SUCCESS) exit
    end do
    msg = mpmc_context_last_error(ctx)
    if (ierr /= MPMC_ERR_SOLVER) then
      write (*, '(a,i0,a,i0,2a)') 'FAILED: wrong df/dtau: expected MPMC_ERR_SOLVER (', &
        MPMC_ERR_SOLVER, '), got ', ierr, ': ', msg
      nfail = nfail + 1
    end if
    if (index(msg, 'user yield surface') == 0 .or. index(msg, 'did not converge') == 0 .or. &
        index(msg, 'dfdtau') == 0) then
      write (*, '(2a)') 'FAILED: wrong df/dtau: expected a message saying the user yield ', &
        'surface did not converge and naming dfdtau, got: '//msg
      nfail = nfail + 1
    end if
    if (getenv_set('T422_VERBOSE')) write (*, '(a,i0,2a)') 'wrong dfdtau: step ', step, ': ', msg
    call ok(mpmc_sim_destroy(s), 'destroy')
    call ok(mpmc_context_destroy(ctx), 'destroy context')
  end subroutine wrong_derivative

  logical function getenv_set(name)
    character(*), intent(in) :: name
    integer :: length
    call get_environment_variable(name, length=length)
    getenv_set = length > 0
  end function getenv_set

  subroutine ok(ierr, what)
    integer(c_int), intent(in) :: ierr
    character(*), intent(in) :: what
    if (ierr /= MPMC_SUCCESS) then
      write (*, '(a,a,a,i0)') 'FAILED: ', what, ' returned ', ierr
      nfail = nfail + 1
    end if
  end subroutine ok

end program t422_user_yield_f
