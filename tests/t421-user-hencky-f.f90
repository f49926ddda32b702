! A user material written in Fortran (UMAT-style bind(C) callback registered with c_funloc)
! runs inside the C time step on 2 OpenMP threads: a Fortran Hencky-elastic update gives the
! built-in mpmc_sim_add_material_hencky's stresses and elastic left Cauchy-Green tensors to
! 1e-12, in 2D and 3D, with and without F-bar, called from both threads of the step; a
! callback that fails stops the step with
! MPMC_ERR_SOLVER and a message naming the point.
module t421_umat
  use, intrinsic :: iso_c_binding, only: c_int, c_long, c_double, c_ptr, c_f_pointer
  implicit none
  private
  public :: hencky_params, hencky_umat, failing_umat, pthread_self

  interface
    !> The calling thread (pthread_t is an unsigned long on Linux).
    function pthread_self() bind(C, name='pthread_self') result(t)
      import :: c_long
      integer(c_long) :: t
    end function pthread_self
  end interface

  !> The model's constants, handed to the callback through its data pointer.
  type, bind(C) :: hencky_params
    real(c_double) :: K, G
  end type hencky_params

contains

  !> Hencky elasticity: b = dF b dF^T, eps_a = ln(lambda_a)/2 from the eigenvalues of b,
  !> tau_a = K tr(eps) + 2G dev(eps)_a, sigma = tau / J.  state(1:6) holds b (Voigt); it
  !> starts at zero, which b can never be (b_xx > 0), so zero means "undeformed".
  !> state(7) records the calling thread (its bits), to show that several threads call it.
  !> recursive + no SAVE: several threads call it at once.
  recursive function hencky_umat(data, dF, dt, state, stress) bind(C) result(ierr)
    type(c_ptr), value :: data
    real(c_double), intent(in) :: dF(3, 3)
    real(c_double), value :: dt
    real(c_double), intent(inout) :: state(*)
    real(c_double), intent(inout) :: stress(6)
    integer(c_int) :: ierr
    type(hencky_params), pointer :: prm
    real(c_double) :: F(3, 3), B(3, 3), T(3, 3), R(3, 3), Q(3, 3), lam(3), eps(3), tau(3), tr
    integer :: i, j
    call c_f_pointer(data, prm)
    if (state(1) == 0.0_c_double) state(1:6) = [1, 1, 1, 0, 0, 0]
    F = transpose(dF) ! C row-major: dF(j, i) = F_ij
    B = voigt_to_mat(state(1:6))
    do j = 1, 3
      do i = 1, 3
        T(i, j) = F(i, 1)*B(1, j) + F(i, 2)*B(2, j) + F(i, 3)*B(3, j)
      end do
    end do
    do j = 1, 3
      do i = 1, 3
        R(i, j) = T(i, 1)*F(j, 1) + T(i, 2)*F(j, 2) + T(i, 3)*F(j, 3)
      end do
    end do
    state(1:6) = [R(1, 1), R(2, 2), R(3, 3), 0.5_c_double*(R(2, 3) + R(3, 2)), &
                  0.5_c_double*(R(1, 3) + R(3, 1)), 0.5_c_double*(R(1, 2) + R(2, 1))]
    call sym3_eig(state(1:6), lam, Q)
    eps = 0.5_c_double*log(lam)
    tr = eps(1) + eps(2) + eps(3)
    tau = (prm%K*tr + 2*prm%G*(eps - tr/3))*exp(-tr)
    do i = 1, 3
      do j = i, 3
        R(i, j) = tau(1)*Q(i, 1)*Q(j, 1) + tau(2)*Q(i, 2)*Q(j, 2) + tau(3)*Q(i, 3)*Q(j, 3)
      end do
    end do
    stress = [R(1, 1), R(2, 2), R(3, 3), R(2, 3), R(1, 3), R(1, 2)]
    state(7) = transfer(pthread_self(), 0.0_c_double)
    ierr = 0
    if (dt <= 0) ierr = 1
  end function hencky_umat

  !> Refuses every update (as a UMAT asks for a smaller step): the step must stop with
  !> MPMC_ERR_SOLVER.  It has no state and no data.
  recursive function failing_umat(data, dF, dt, state, stress) bind(C) result(ierr)
    type(c_ptr), value :: data
    real(c_double), intent(in) :: dF(3, 3)
    real(c_double), value :: dt
    real(c_double), intent(inout) :: state(*)
    real(c_double), intent(inout) :: stress(6)
    integer(c_int) :: ierr
    ierr = 7
  end function failing_umat

  pure function voigt_to_mat(s) result(A)
    real(c_double), intent(in) :: s(6)
    real(c_double) :: A(3, 3)
    A = reshape([s(1), s(6), s(5), s(6), s(2), s(4), s(5), s(4), s(3)], [3, 3])
  end function voigt_to_mat

  !> Eigen-decomposition of a symmetric 3x3 tensor (Voigt s) by cyclic Jacobi:
  !> s = sum_a lam(a) Q(:, a) Q(:, a)^T.
  pure subroutine sym3_eig(s, lam, Q)
    real(c_double), intent(in) :: s(6)
    real(c_double), intent(out) :: lam(3), Q(3, 3)
    real(c_double) :: A(3, 3), off, diag, apq, theta, t, c, sn, x, y
    integer :: sweep, ip, iq, k
    A = voigt_to_mat(s)
    Q = reshape([1, 0, 0, 0, 1, 0, 0, 0, 1], [3, 3])
    do sweep = 1, 32
      off = A(1, 2)**2 + A(1, 3)**2 + A(2, 3)**2
      diag = A(1, 1)**2 + A(2, 2)**2 + A(3, 3)**2
      if (off <= 1.0e-36_c_double*diag .or. off == 0) exit
      do ip = 1, 2
        do iq = ip + 1, 3
          apq = A(ip, iq)
          if (apq == 0) cycle
          theta = (A(iq, iq) - A(ip, ip))/(2*apq)
          t = sign(1.0_c_double, theta)/(abs(theta) + sqrt(theta*theta + 1))
          c = 1/sqrt(t*t + 1)
          sn = t*c
          do k = 1, 3 ! A <- A J
            x = A(k, ip)
            y = A(k, iq)
            A(k, ip) = c*x - sn*y
            A(k, iq) = sn*x + c*y
          end do
          do k = 1, 3 ! A <- J^T A
            x = A(ip, k)
            y = A(iq, k)
            A(ip, k) = c*x - sn*y
            A(iq, k) = sn*x + c*y
          end do
          do k = 1, 3 ! Q <- Q J
            x = Q(k, ip)
            y = Q(k, iq)
            Q(k, ip) = c*x - sn*y
            Q(k, iq) = sn*x + c*y
          end do
        end do
      end do
    end do
    lam = [A(1, 1), A(2, 2), A(3, 3)]
  end subroutine sym3_eig

end module t421_umat

program t421_user_hencky_f
  use, intrinsic :: iso_c_binding, only: c_int, c_long, c_double, c_loc, c_funloc, c_null_ptr
  use mpmc
  use t421_umat
  implicit none
  real(c_double), parameter :: E = 1.0e6_c_double, nu = 0.3_c_double, rho = 1000.0_c_double
  type(hencky_params), target :: prm
  integer :: nfail

  nfail = 0
  prm%K = E/(3*(1 - 2*nu))
  prm%G = E/(2*(1 + nu))
  call compare(2, 0)
  call compare(2, 1)
  call compare(3, 1)
  call compare(2, int(MPMC_FBAR_STABLE))
  call failing()
  if (nfail > 0) error stop 1

contains

  ! Build the same block twice, once with each material, and step both on 2 threads.
  subroutine compare(dim, fbar)
    integer, intent(in) :: dim, fbar
    ! 10 steps to a few per cent strain: the two updates differ by round-off (about one ulp
    ! of b per step), which the Hencky stress amplifies by 1/strain at small strain.
    integer, parameter :: nsteps = 10
    type(mpmc_context) :: ctx
    type(mpmc_sim) :: sim(2)
    real(c_double), pointer :: s1(:, :), s2(:, :), b1(:, :), st(:, :), x1(:, :), x2(:, :)
    real(c_double), allocatable :: x(:, :), vol(:)
    real(c_double) :: dt, smax, err, berr, xerr, c
    integer(c_int) :: k, mat, first, n
    integer :: step, q, nthreads
    integer(c_long) :: tid, seen(8)
    character(len=64) :: label

    write (label, '(a,i0,a,i0)') 'dim ', dim, ', fbar ', fbar
    call ok(mpmc_context_create(ctx), 'context')
    c = sqrt((prm%K + 4*prm%G/3)/rho) ! the built-in's p-wave speed
    call block(dim, x, vol)
    n = int(size(vol), c_int)
    do k = 1, 2
      call ok(mpmc_sim_create(ctx, int(dim, c_int), sim(k)), 'sim')
      call ok(mpmc_sim_set_grid(sim(k), [0.0_c_double, 0.0_c_double, 0.0_c_double], &
        [2.0_c_double, 2.0_c_double, 2.0_c_double], 0.25_c_double), 'grid')
      call ok(mpmc_sim_set_fbar(sim(k), int(fbar, c_int)), 'fbar')
      call ok(mpmc_sim_set_threads(sim(k), 2_c_int), 'threads')
      if (k == 1) then
        call ok(mpmc_sim_add_material_hencky(sim(k), E, nu, rho, mat), 'built-in hencky')
      else
        call ok(mpmc_sim_add_material_user(sim(k), c_funloc(hencky_umat), c_loc(prm), 7_c_int, &
          rho, c, mat), 'user hencky')
      end if
      call ok(mpmc_sim_add_particles(sim(k), n, x, vol, mat, first), 'points')
      call set_velocity(sim(k), dim)
    end do
    call ok(mpmc_sim_stable_dt(sim(1), 0.3_c_double, dt), 'stable dt')
    do step = 1, nsteps
      do k = 1, 2
        call ok(mpmc_sim_step(sim(k), dt), 'step')
      end do
    end do
    call ok(mpmc_sim_get_field(sim(1), MPMC_FIELD_STRESS, s1), 'stress 1')
    call ok(mpmc_sim_get_field(sim(2), MPMC_FIELD_STRESS, s2), 'stress 2')
    call ok(mpmc_sim_get_field(sim(1), MPMC_FIELD_BE, b1), 'be 1')
    call ok(mpmc_sim_get_user_state(sim(2), mat, st), 'user state')
    call ok(mpmc_sim_get_field(sim(1), MPMC_FIELD_POSITION, x1), 'x 1')
    call ok(mpmc_sim_get_field(sim(2), MPMC_FIELD_POSITION, x2), 'x 2')
    if (nfail > 0) return
    smax = maxval(abs(s1))
    err = maxval(abs(s2 - s1))/smax
    berr = maxval(abs(st(1:6, :) - b1))
    xerr = maxval(abs(x2 - x1))
    ! the block must really be strained: |sigma| well above round-off of E
    if (.not. smax > 1.0e-3_c_double*E) then
      write (*, '(3a,es12.4)') 'FAILED: ', trim(label), ': expected max |stress| > 1e3 Pa, got ', smax
      nfail = nfail + 1
    end if
    if (.not. err <= 1.0e-12_c_double) then
      write (*, '(3a,es12.4)') 'FAILED: ', trim(label), &
        ': user stress vs built-in: expected relative difference <= 1e-12, got ', err
      nfail = nfail + 1
    end if
    if (.not. berr <= 1.0e-12_c_double) then
      write (*, '(3a,es12.4)') 'FAILED: ', trim(label), &
        ': user state vs built-in be: expected difference <= 1e-12, got ', berr
      nfail = nfail + 1
    end if
    if (.not. xerr <= 1.0e-12_c_double) then
      write (*, '(3a,es12.4)') 'FAILED: ', trim(label), &
        ': positions: expected difference <= 1e-12 m, got ', xerr
      nfail = nfail + 1
    end if
    ! the callback ran on both threads of the step's OpenMP loop
    nthreads = 0
    do q = 1, size(st, 2)
      tid = transfer(st(7, q), tid)
      if (all(seen(1:nthreads) /= tid)) then
        if (nthreads < size(seen)) nthreads = nthreads + 1
        seen(nthreads) = tid
      end if
    end do
    if (nthreads /= 2) then
      write (*, '(3a,i0)') 'FAILED: ', trim(label), &
        ': expected the callback to run on 2 threads, it ran on ', nthreads
      nfail = nfail + 1
    end if
    do k = 1, 2
      call ok(mpmc_sim_destroy(sim(k)), 'destroy')
    end do
    call ok(mpmc_context_destroy(ctx), 'destroy context')
  end subroutine compare

  ! 2 points per cell per axis in the box [0.5, 1.5]^dim (cells of 0.25).
  subroutine block(dim, x, vol)
    integer, intent(in) :: dim
    real(c_double), allocatable, intent(out) :: x(:, :), vol(:)
    integer :: i, j, k, q, nk
    real(c_double), parameter :: dx = 0.125_c_double
    nk = 1
    if (dim == 3) nk = 8
    allocate (x(dim, 8*8*nk), vol(8*8*nk))
    q = 0
    do k = 1, nk
      do j = 1, 8
        do i = 1, 8
          q = q + 1
          x(1, q) = 0.5_c_double + (i - 0.5_c_double)*dx
          x(2, q) = 0.5_c_double + (j - 0.5_c_double)*dx
          if (dim == 3) x(3, q) = 0.5_c_double + (k - 0.5_c_double)*dx
        end do
      end do
    end do
    vol = dx**dim
  end subroutine block

  ! A non-uniform initial velocity (stretch, shear and rotation), written in place.
  subroutine set_velocity(s, dim)
    type(mpmc_sim), intent(in) :: s
    integer, intent(in) :: dim
    real(c_double), pointer :: v(:, :), xp(:, :)
    real(c_double), parameter :: vamp = 5
    call ok(mpmc_sim_get_field(s, MPMC_FIELD_VELOCITY, v), 'velocity')
    call ok(mpmc_sim_get_field(s, MPMC_FIELD_POSITION, xp), 'position')
    v(1, :) = vamp*(0.4_c_double*(xp(1, :) - 1) + 0.3_c_double*(xp(2, :) - 1)**2)
    v(2, :) = vamp*(-0.2_c_double*(xp(2, :) - 1) + 0.5_c_double*sin(3*xp(1, :)))
    if (dim == 3) v(3, :) = vamp*0.3_c_double*(xp(3, :) - 1)*(xp(1, :) - 1)
    call ok(mpmc_sim_restore_field(s, MPMC_FIELD_VELOCITY, v), 'restore velocity')
    call ok(mpmc_sim_restore_field(s, MPMC_FIELD_POSITION, xp), 'restore position')
  end subroutine set_velocity

  subroutine failing()
    type(mpmc_context) :: ctx
    type(mpmc_sim) :: s
    integer(c_int) :: mat, first, ierr
    character(len=:), allocatable :: msg
    call ok(mpmc_context_create(ctx), 'context')
    call ok(mpmc_sim_create(ctx, 2_c_int, s), 'sim')
    call ok(mpmc_sim_set_grid(s, [0.0_c_double, 0.0_c_double], [1.0_c_double, 1.0_c_double], &
      0.25_c_double), 'grid')
    call ok(mpmc_sim_set_threads(s, 2_c_int), 'threads')
    call ok(mpmc_sim_add_material_user(s, c_funloc(failing_umat), c_null_ptr, 0_c_int, rho, &
      10.0_c_double, mat), 'failing user material')
    call ok(mpmc_sim_add_particles(s, 2_c_int, [0.4_c_double, 0.4_c_double, 0.6_c_double, &
      0.6_c_double], [0.01_c_double, 0.01_c_double], mat, first), 'points')
    ierr = mpmc_sim_step(s, 1.0e-3_c_double)
    msg = mpmc_context_last_error(ctx)
    if (ierr /= MPMC_ERR_SOLVER) then
      write (*, '(a,i0,a,i0)') 'FAILED: failing callback: expected code ', MPMC_ERR_SOLVER, &
        ', got ', ierr
      nfail = nfail + 1
    end if
    if (index(msg, 'user material 0 stress function failed at point 0') == 0 .or. &
        index(msg, '(returned 7)') == 0) then
      write (*, '(a,a)') 'FAILED: failing callback: expected a message naming point 0 and code 7, got ', msg
      nfail = nfail + 1
    end if
    ierr = mpmc_sim_add_material_user(s, c_funloc(failing_umat), c_null_ptr, -1_c_int, rho, &
      10.0_c_double, mat)
    if (ierr /= MPMC_ERR_ARG .or. index(mpmc_context_last_error(ctx), 'nstate = -1 must be in [0, 4096]') == 0) then
      write (*, '(a,i0,2a)') 'FAILED: nstate = -1: expected MPMC_ERR_ARG and a message naming nstate, got ', &
        ierr, ': ', mpmc_context_last_error(ctx)
      nfail = nfail + 1
    end if
    call ok(mpmc_sim_destroy(s), 'destroy')
    call ok(mpmc_context_destroy(ctx), 'destroy context')
  end subroutine failing

  subroutine ok(ierr, what)
    integer(c_int), intent(in) :: ierr
    character(*), intent(in) :: what
    if (ierr /= MPMC_SUCCESS) then
      write (*, '(a,a,a,i0)') 'FAILED: ', what, ' returned ', ierr
      nfail = nfail + 1
    end if
  end subroutine ok

end program t421_user_hencky_f
