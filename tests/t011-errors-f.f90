! Fortran twin of the error tests: a failing call returns its code and the context's message
! reads as an ordinary Fortran string; error strings match the C X-macro list; the energy
! monitor's factor reaches C by value (a bad one is named in the message).
program t011_errors_f
  use, intrinsic :: iso_c_binding, only: c_int, c_double
  use mpmc
  implicit none
  type(mpmc_context) :: ctx
  type(mpmc_sim) :: sim
  integer(c_int) :: ierr, id, mat, first, major, minor, patch, dim
  character(len=:), allocatable :: msg
  integer :: nfail

  nfail = 0
  call check(mpmc_context_create(ctx) == MPMC_SUCCESS, 'mpmc_context_create succeeds')

  ! a bad dimension: the code and a message naming the parameter
  ierr = mpmc_sim_create(ctx, 4_c_int, sim)
  call expect_int('mpmc_sim_create(dim = 4)', MPMC_ERR_ARG, ierr)
  msg = mpmc_context_last_error(ctx)
  call expect_has('message of mpmc_sim_create(dim = 4)', msg, 'dimension dim = 4 must be 2 or 3')
  call check(index(msg, 'invalid argument: ') == 1, 'message starts with the code''s text')
  ! the buffer form gives the same text
  call check(mpmc_context_get_last_error(ctx, msg) == MPMC_SUCCESS, 'get_last_error succeeds')
  call expect_has('mpmc_context_get_last_error', msg, 'dimension dim = 4 must be 2 or 3')
  call check(.not. c_handle_set(sim), 'no simulation handle after the failure')

  ! a valid simulation, then bad material parameters
  call check(mpmc_sim_create(ctx, 2_c_int, sim) == MPMC_SUCCESS, 'mpmc_sim_create(dim = 2)')
  call check(mpmc_sim_get_dim(sim, dim) == MPMC_SUCCESS .and. dim == 2, 'mpmc_sim_get_dim = 2')
  ierr = mpmc_sim_add_material_hencky(sim, 1.0e6_c_double, 0.5_c_double, 2000.0_c_double, id)
  call expect_int('hencky with nu = 0.5', MPMC_ERR_ARG, ierr)
  call expect_has('message of nu = 0.5', mpmc_context_last_error(ctx), &
    "Poisson's ratio nu = 0.5 must be in [0, 0.5)")
  ! a user material without a function
  ierr = mpmc_sim_add_material_user(sim, c_null_funptr_value(), c_null_ptr_value(), 0_c_int, &
    1000.0_c_double, 10.0_c_double, id)
  call expect_int('user material with fn = NULL', MPMC_ERR_ARG, ierr)
  call expect_has('message of fn = NULL', mpmc_context_last_error(ctx), &
    'stress function fn is NULL')
  ! out of order: points before the grid
  ierr = mpmc_sim_add_particles(sim, 1_c_int, [0.5_c_double, 0.5_c_double], [1.0_c_double], &
    0_c_int, first)
  call expect_int('add_particles before set_grid', MPMC_ERR_STATE, ierr)
  call expect_has('message of add_particles before set_grid', mpmc_context_last_error(ctx), &
    'set the grid before adding material points')
  ! a particle outside the grid box
  call check(mpmc_sim_set_grid(sim, [0.0_c_double, 0.0_c_double], [1.0_c_double, 1.0_c_double], &
    0.25_c_double) == MPMC_SUCCESS, 'mpmc_sim_set_grid')
  call check(mpmc_sim_add_material_hencky(sim, 1.0e6_c_double, 0.3_c_double, 2000.0_c_double, &
    mat) == MPMC_SUCCESS, 'hencky with valid parameters')
  ierr = mpmc_sim_add_particles(sim, 1_c_int, [1.5_c_double, 0.5_c_double], [0.01_c_double], mat, first)
  call expect_int('a point outside the box', MPMC_ERR_OUTSIDE, ierr)
  call expect_has('message of the point outside', mpmc_context_last_error(ctx), &
    'coordinate 0 = 1.5 outside the grid box [0, 1]')
  ! kernel sets: a bad value names the parameter; BASELINE is always there and reads back
  ierr = mpmc_sim_set_kernels(sim, 7_c_int)
  call expect_int('mpmc_sim_set_kernels(7)', MPMC_ERR_ARG, ierr)
  call expect_has('message of set_kernels(7)', mpmc_context_last_error(ctx), 'kernels = 7')
  call check(mpmc_sim_set_kernels(sim, MPMC_KERNELS_BASELINE) == MPMC_SUCCESS, 'set_kernels(BASELINE)')
  call check(mpmc_sim_get_kernels(sim, id) == MPMC_SUCCESS .and. id == MPMC_KERNELS_BASELINE, &
    'get_kernels = BASELINE')
  call check(mpmc_sim_set_kernels(sim, MPMC_KERNELS_AUTO) == MPMC_SUCCESS, 'set_kernels(AUTO)')
  call check(mpmc_sim_get_kernels(sim, id) == MPMC_SUCCESS .and. (id == MPMC_KERNELS_BASELINE &
    .or. id == MPMC_KERNELS_FMA .or. id == MPMC_KERNELS_AVX512), 'get_kernels after AUTO is a concrete set')
  call expect_str('mpmc_kernels_name(MPMC_KERNELS_FMA)', 'fma', mpmc_kernels_name(MPMC_KERNELS_FMA))
  call expect_str('mpmc_kernels_name(MPMC_KERNELS_AVX512)', 'avx512', &
    mpmc_kernels_name(MPMC_KERNELS_AVX512))
  call expect_str('mpmc_kernels_name(MPMC_KERNELS_BASELINE)', 'baseline', &
    mpmc_kernels_name(MPMC_KERNELS_BASELINE))
  call expect_str('mpmc_kernels_name(7)', 'unknown kernel set', mpmc_kernels_name(7_c_int))
  ! the run monitor's energy factor goes by value: 0.5 is refused and named, factors above 1,
  ! the default (0) and off (< 0) are taken
  ierr = mpmc_sim_set_energy_monitor(sim, 0.5_c_double)
  call expect_int('mpmc_sim_set_energy_monitor(0.5)', MPMC_ERR_ARG, ierr)
  call expect_has('message of set_energy_monitor(0.5)', mpmc_context_last_error(ctx), &
    'energy monitor factor = 0.5 must be > 1')
  call check(mpmc_sim_set_energy_monitor(sim, 2.0_c_double) == MPMC_SUCCESS, &
    'set_energy_monitor(2)')
  call check(mpmc_sim_set_energy_monitor(sim, MPMC_MONITOR_ENERGY_FACTOR) == MPMC_SUCCESS, &
    'set_energy_monitor(MPMC_MONITOR_ENERGY_FACTOR)')
  call check(mpmc_sim_set_energy_monitor(sim, 0.0_c_double) == MPMC_SUCCESS, &
    'set_energy_monitor(0): the default')
  call check(mpmc_sim_set_energy_monitor(sim, -1.0_c_double) == MPMC_SUCCESS, &
    'set_energy_monitor(-1): off')
  ! clearing forgets the message
  call check(mpmc_context_clear_error(ctx) == MPMC_SUCCESS, 'mpmc_context_clear_error')
  call expect_str('message after clear', '', mpmc_context_last_error(ctx))

  ! the code list agrees with the C X-macro
  call expect_str('mpmc_error_string(MPMC_SUCCESS)', 'success', mpmc_error_string(MPMC_SUCCESS))
  call expect_str('mpmc_error_string(MPMC_ERR_ARG)', 'invalid argument', &
    mpmc_error_string(MPMC_ERR_ARG))
  call expect_str('mpmc_error_string(MPMC_ERR_UNSUPPORTED)', 'not supported in this build', &
    mpmc_error_string(MPMC_ERR_UNSUPPORTED))
  call expect_str('mpmc_error_string(MPMC_ERROR_COUNT)', 'unknown error code', &
    mpmc_error_string(MPMC_ERROR_COUNT))
  call check(mpmc_version(major, minor, patch) == MPMC_SUCCESS, 'mpmc_version')
  call expect_int('version major', MPMC_VERSION_MAJOR, major)
  call expect_int('version minor', MPMC_VERSION_MINOR, minor)
  call expect_int('version patch', MPMC_VERSION_PATCH, patch)

  ! destroy sets the handles to null and accepts them again
  call check(mpmc_sim_destroy(sim) == MPMC_SUCCESS, 'mpmc_sim_destroy')
  call check(.not. c_handle_set(sim), 'sim handle null after destroy')
  call check(mpmc_sim_destroy(sim) == MPMC_SUCCESS, 'mpmc_sim_destroy of a null handle')
  call check(mpmc_context_destroy(ctx) == MPMC_SUCCESS, 'mpmc_context_destroy')
  call expect_str('message of a null context', 'no context', mpmc_context_last_error(ctx))

  deallocate (msg) ! main-program variables are not freed automatically
  if (nfail > 0) error stop 1

contains

  logical function c_handle_set(s)
    use, intrinsic :: iso_c_binding, only: c_associated
    type(mpmc_sim), intent(in) :: s
    c_handle_set = c_associated(s%ptr)
  end function

  function c_null_funptr_value() result(f)
    use, intrinsic :: iso_c_binding, only: c_funptr, c_null_funptr
    type(c_funptr) :: f
    f = c_null_funptr
  end function

  function c_null_ptr_value() result(p)
    use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr
    type(c_ptr) :: p
    p = c_null_ptr
  end function

  subroutine check(ok, what)
    logical, intent(in) :: ok
    character(*), intent(in) :: what
    if (.not. ok) then
      write (*, '(a,a)') 'FAILED: ', what
      write (*, '(a,a)') '  last error: ', mpmc_context_last_error(ctx)
      nfail = nfail + 1
    end if
  end subroutine

  subroutine expect_int(what, expected, got)
    character(*), intent(in) :: what
    integer(c_int), intent(in) :: expected, got
    if (expected /= got) then
      write (*, '(a,a,a,i0,a,i0)') 'FAILED: ', what, ': expected ', expected, ', got ', got
      nfail = nfail + 1
    end if
  end subroutine

  subroutine expect_str(what, expected, got)
    character(*), intent(in) :: what, expected, got
    if (expected /= got .or. len(expected) /= len(got)) then
      write (*, '(a,a,a,a,a,a,a)') 'FAILED: ', what, ': expected "', expected, '", got "', got, '"'
      nfail = nfail + 1
    end if
  end subroutine

  subroutine expect_has(what, text, part)
    character(*), intent(in) :: what, text, part
    if (index(text, part) == 0) then
      write (*, '(a,a,a,a,a,a,a)') 'FAILED: ', what, ': expected a message containing "', part, &
        '", got "', text, '"'
      nfail = nfail + 1
    end if
  end subroutine

end program t011_errors_f
