! Fortran twin of the output and checkpoint tests, with a Fortran user material: a snapshot
! is written, a checkpoint written with a meta text is read back into a new simulation with
! the same points, the same meta text and the user material's state; the restored user
! material refuses to step until its Fortran callback is re-attached, then carries on; a
! second user material with more state widens the state rows and keeps the values.
module t642_umat
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_ptr
  implicit none
  private
  public :: counting_umat
contains
  !> Counts its calls per point in state(1) and keeps the stress (a rigid material).
  recursive function counting_umat(data, dF, dt, state, stress) bind(C) result(ierr)
    type(c_ptr), value :: data
    real(c_double), intent(in) :: dF(3, 3)
    real(c_double), value :: dt
    real(c_double), intent(inout) :: state(*)
    real(c_double), intent(inout) :: stress(6)
    integer(c_int) :: ierr
    state(1) = state(1) + 1
    ierr = 0
  end function counting_umat
end module t642_umat

program t642_checkpoint_user_f
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_funloc, c_null_ptr
  use mpmc
  use t642_umat
  implicit none
  type(mpmc_context) :: ctx
  type(mpmc_sim) :: sim, back
  type(mpmc_output) :: out
  integer(c_int) :: mat, mat2, first, count, n, ierr
  integer :: step
  real(c_double), pointer :: x(:, :), xb(:, :), st(:, :)
  character(len=:), allocatable :: meta, msg
  character(len=*), parameter :: dir = 't642-checkpoint-user-f.out'
  logical :: exists
  integer :: nfail

  nfail = 0
  call execute_command_line('mkdir -p '//dir)
  call ok(mpmc_context_create(ctx), 'context')
  call ok(mpmc_sim_create(ctx, 2_c_int, sim), 'sim')
  call ok(mpmc_sim_set_grid(sim, [0.0_c_double, 0.0_c_double], [2.0_c_double, 2.0_c_double], &
    0.25_c_double), 'grid')
  call ok(mpmc_sim_add_material_user(sim, c_funloc(counting_umat), c_null_ptr, 2_c_int, &
    1000.0_c_double, 100.0_c_double, mat), 'user material')
  call ok(mpmc_sim_seed_box(sim, [0.5_c_double, 0.5_c_double], [1.0_c_double, 1.5_c_double], &
    2_c_int, mat, first, count), 'seed box')
  ! 2 x 4 cells of 0.25 m, 2 x 2 points each
  call expect_int('points seeded', 32, count)
  call ok(mpmc_sim_set_gravity(sim, [0.0_c_double, -9.81_c_double]), 'gravity')
  do step = 1, 3
    call ok(mpmc_sim_step(sim, 1.0e-4_c_double), 'step')
  end do

  call ok(mpmc_output_create(sim, dir//'/snap.h5', dir//'/snap.xdmf', out), 'output create')
  call ok(mpmc_output_write(out), 'output write')
  call ok(mpmc_output_destroy(out), 'output destroy')
  inquire (file=dir//'/snap.h5', exist=exists)
  if (.not. exists) call fail('expected '//dir//'/snap.h5 after mpmc_output_write')

  call ok(mpmc_sim_checkpoint_write(sim, dir//'/ckpt.h5', 'stage 2 of 3'), 'checkpoint write')
  call ok(mpmc_sim_checkpoint_read(ctx, dir//'/ckpt.h5', back, meta), 'checkpoint read')
  if (meta /= 'stage 2 of 3') call fail('meta: expected "stage 2 of 3", got "'//meta//'"')
  call ok(mpmc_sim_get_num_particles(back, n), 'number of points')
  call expect_int('points after restart', int(count), int(n))
  call ok(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, x), 'positions')
  call ok(mpmc_sim_get_field(back, MPMC_FIELD_POSITION, xb), 'restored positions')
  if (maxval(abs(xb - x)) /= 0) call fail('restored positions differ from the saved ones')
  call ok(mpmc_sim_get_user_state(back, mat, st), 'restored user state')
  call expect_int('user state rows', 2, size(st, 1))
  if (any(st(1, :) /= 3)) call fail('restored user state: expected 3 calls per point')

  ! the callback is not in the file: stepping must fail until it is re-attached
  ierr = mpmc_sim_step(back, 1.0e-4_c_double)
  msg = mpmc_context_last_error(ctx)
  if (ierr /= MPMC_ERR_STATE .or. index(msg, 'mpmc_sim_set_material_user_fn') == 0) &
    call fail('step before re-attaching: expected MPMC_ERR_STATE naming mpmc_sim_set_material_user_fn, got '// &
              itoa(ierr)//': '//msg)
  call ok(mpmc_sim_set_material_user_fn(back, mat, c_funloc(counting_umat), c_null_ptr), 're-attach')
  call ok(mpmc_sim_step(back, 1.0e-4_c_double), 'step after re-attaching')
  call ok(mpmc_sim_get_user_state(back, mat, st), 'user state')
  if (any(st(1, :) /= 4)) call fail('user state after one more step: expected 4 calls per point')

  ! a second user material with more state widens every point's row, keeping the values
  call ok(mpmc_sim_add_material_user(sim, c_funloc(counting_umat), c_null_ptr, 4_c_int, &
    1000.0_c_double, 100.0_c_double, mat2), 'second user material')
  call ok(mpmc_sim_get_user_state(sim, mat2, st), 'widened user state')
  call expect_int('widened user state rows', 4, size(st, 1))
  call expect_int('widened user state columns', int(count), size(st, 2))
  if (any(st(1, :) /= 3) .or. any(st(2:4, :) /= 0)) &
    call fail('widened user state: expected (3, 0, 0, 0) on every point')

  call ok(mpmc_sim_destroy(back), 'destroy restored')
  call ok(mpmc_sim_destroy(sim), 'destroy')
  call ok(mpmc_context_destroy(ctx), 'destroy context')
  deallocate (meta, msg)
  if (nfail > 0) error stop 1

contains

  function itoa(i) result(s)
    integer(c_int), intent(in) :: i
    character(len=12) :: s
    write (s, '(i0)') i
  end function itoa

  subroutine fail(what)
    character(*), intent(in) :: what
    write (*, '(a,a)') 'FAILED: ', what
    nfail = nfail + 1
  end subroutine fail

  subroutine ok(code, what)
    integer(c_int), intent(in) :: code
    character(*), intent(in) :: what
    if (code /= MPMC_SUCCESS) call fail(what//' returned '//trim(itoa(code))//': '// &
                                        mpmc_context_last_error(ctx))
  end subroutine ok

  subroutine expect_int(what, expected, got)
    character(*), intent(in) :: what
    integer, intent(in) :: expected, got
    if (expected /= got) call fail(what//': expected '//trim(itoa(int(expected, c_int)))// &
                                   ', got '//trim(itoa(int(got, c_int))))
  end subroutine expect_int

end program t642_checkpoint_user_f
