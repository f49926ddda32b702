! Fortran twin of `mpmc resume` (t651 test_check_and_resume): mpmc_workflow_run, then
! mpmc_workflow_resume without overrides (the C mpmc_workflow_resume) and with them
! (mpmc_workflow_resume_set).  A free fall from rest at dt = 1 ms takes one step a
! millisecond, so summary.json counts the steps of every stage run:
!  - the finished two-stage run (10 + 10 steps) is refused, the message naming its directory
!    and its 2 stages, and summary.json keeps its 20 steps;
!  - with a third stage of 10 ms in the scene, resume runs it alone: 30 steps;
!  - the override stages.third.end.time=0.02 goes on 10 steps more: 40;
!  - a directory without a checkpoint is named in the error.
! The directory is passed blank-padded (the wrappers trim and NUL-terminate it), and every
! call is quiet: CTest fails this test on any log line of the front end ("mpmc: "), so flags
! must reach C too.
program t653_workflow_resume_f
  use, intrinsic :: iso_c_binding, only: c_int
  use mpmc
  implicit none
  character(*), parameter :: scene = 't653-fall.yaml', out = 't653-out'
  type(mpmc_context) :: ctx
  character(len=40) :: dir ! out padded with blanks, as a Fortran program holds a path
  integer(c_int) :: ierr
  integer :: nfail

  nfail = 0
  dir = out
  call check(mpmc_context_create(ctx) == MPMC_SUCCESS, 'mpmc_context_create')
  call write_scene(.false.)
  ierr = mpmc_workflow_run(ctx, scene, out, flags=MPMC_WORKFLOW_FORCE + MPMC_WORKFLOW_QUIET)
  call expect_int('mpmc_workflow_run of the two-stage scene', MPMC_SUCCESS, ierr)
  call expect_int('steps after the run', 20, summary_steps())

  ! the checkpoint is the finished run: nothing to resume
  ierr = mpmc_workflow_resume(ctx, dir, MPMC_WORKFLOW_QUIET)
  call expect_int('mpmc_workflow_resume of a finished run', MPMC_ERR_STATE, ierr)
  call expect_has('message of resuming a finished run', mpmc_context_last_error(ctx), &
    'resume: the run in '//out//' finished all 2 stages')
  call expect_int('steps after a refused resume', 20, summary_steps())

  ! a third stage in the scene: resume runs it alone
  call write_scene(.true.)
  ierr = mpmc_workflow_resume(ctx, dir, MPMC_WORKFLOW_QUIET)
  call expect_int('mpmc_workflow_resume with a third stage', MPMC_SUCCESS, ierr)
  call expect_int('steps after resuming the third stage', 30, summary_steps())

  ! an override after the run's own: the third stage ends 10 ms later
  ierr = mpmc_workflow_resume(ctx, dir, MPMC_WORKFLOW_QUIET, ['stages.third.end.time=0.02'])
  call expect_int('mpmc_workflow_resume with stages.third.end.time=0.02', MPMC_SUCCESS, ierr)
  call expect_int('steps after the override', 40, summary_steps())

  ! no checkpoint: the path is named
  ierr = mpmc_workflow_resume(ctx, 't653-none', MPMC_WORKFLOW_QUIET)
  call check(ierr /= MPMC_SUCCESS, 'mpmc_workflow_resume of a directory without a checkpoint fails')
  call expect_has('message of resuming t653-none', mpmc_context_last_error(ctx), &
    't653-none/checkpoint.h5')

  call check(mpmc_context_destroy(ctx) == MPMC_SUCCESS, 'mpmc_context_destroy')
  if (nfail > 0) error stop 1

contains

  ! The free-fall scene of t651 with stages of 10 ms; a third one when `third`.
  subroutine write_scene(third)
    logical, intent(in) :: third
    integer :: u
    open (newunit=u, file=scene, status='replace', action='write')
    write (u, '(a)') 'scene: fall', 'dim: 2', 'grid: {lo: [0, -1], hi: [2, 2], cell_size: 0.5}', &
      'fbar: false', 'plots: false', 'materials:', &
      '  m: {model: hencky, E: 1.0e6, nu: 0.3, rho: 1000}', 'geometry:', &
      '  - {type: box, lo: [0, 0], hi: [1, 1], ppc: 2}', 'stages:', &
      '  - {name: first, gravity: [0, -9.81], dt: 0.001, end: {time: 0.01}}', &
      '  - {name: second, dt: 0.001, end: {time: 0.01}}'
    if (third) write (u, '(a)') '  - {name: third, dt: 0.001, end: {time: 0.01}}'
    close (u)
  end subroutine write_scene

  ! The "steps" of out/summary.json (-1 when the file or the key is missing).
  integer function summary_steps() result(n)
    character(len=:), allocatable :: text
    integer :: u, size_bytes, at, ios
    n = -1
    open (newunit=u, file=out//'/summary.json', access='stream', form='unformatted', &
      action='read', status='old', iostat=ios)
    if (ios /= 0) return
    inquire (unit=u, size=size_bytes)
    allocate (character(len=size_bytes) :: text)
    read (u, iostat=ios) text
    close (u)
    if (ios /= 0) return
    at = index(text, '"steps": ')
    if (at == 0) return
    read (text(at + 9:), *, iostat=ios) n
    if (ios /= 0) n = -1
  end function summary_steps

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
    integer, intent(in) :: expected, got
    if (expected /= got) then
      write (*, '(a,a,a,i0,a,i0)') 'FAILED: ', what, ': expected ', expected, ', got ', got
      write (*, '(a,a)') '  last error: ', mpmc_context_last_error(ctx)
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

end program t653_workflow_resume_f
