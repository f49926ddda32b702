! t704: the Fortran binding over MPI: mpmc_sim_create_mpi_f with the mpi module's integer
! communicator, each rank's slab (mpmc_sim_get_mpi_slab), the column's points shared among
! the ranks (every point on exactly one), 50 steps under gravity, and the kinetic energy, a
! value over all ranks, the same on every rank.  Run with 2 and 3 ranks (fortran/).
program t704_mpi_column_f
  use, intrinsic :: iso_c_binding, only: c_int, c_double
  use mpi
  use mpmc
  implicit none
  type(mpmc_context) :: ctx
  type(mpmc_sim) :: sim
  integer :: ierr, rank, nranks, nfail, j, i, q, ntot, iwall
  integer(c_int) :: r, nr, ax, clo, chi, mat, first, n, wid
  real(c_double) :: x(2, 40), vol(40), ke, kemin, kemax

  nfail = 0
  call MPI_Init(ierr)
  call MPI_Comm_rank(MPI_COMM_WORLD, rank, ierr)
  call MPI_Comm_size(MPI_COMM_WORLD, nranks, ierr)
  call ok(mpmc_context_create(ctx), 'context')
  call ok(mpmc_sim_create_mpi_f(ctx, int(MPI_COMM_WORLD, c_int), 2_c_int, sim), 'sim over MPI')
  call ok(mpmc_sim_set_grid(sim, [0.0_c_double, 0.0_c_double], [1.0_c_double, 11.0_c_double], &
    0.5_c_double), 'grid')
  call ok(mpmc_sim_get_mpi_slab(sim, r, nr, ax, clo, chi), 'slab')
  call expect_int('rank', rank, r)
  call expect_int('ranks', nranks, nr)
  call expect_int('slab axis', 1, ax)
  call ok(mpmc_sim_add_material_hencky(sim, 1.0e7_c_double, 0.3_c_double, 2000.0_c_double, mat), &
    'material')
  q = 0
  do j = 0, 19
    do i = 0, 1
      q = q + 1
      x(:, q) = [0.25_c_double + 0.5_c_double * i, 0.25_c_double + 0.5_c_double * j]
      vol(q) = 0.25_c_double
    end do
  end do
  call ok(mpmc_sim_add_particles(sim, 40_c_int, x, vol, mat, first), 'points')
  call ok(mpmc_sim_get_num_particles(sim, n), 'number of points')
  call MPI_Allreduce(int(n), ntot, 1, MPI_INTEGER, MPI_SUM, MPI_COMM_WORLD, ierr)
  call expect_int('points over the ranks', 40, ntot)
  call ok(mpmc_sim_set_gravity(sim, [0.0_c_double, -9.81_c_double]), 'gravity')
  do iwall = 0, 2
    call ok(mpmc_sim_add_wall_face(sim, int(iwall, c_int), &
      merge(MPMC_WALL_FIXED, MPMC_WALL_SLIP, iwall == 2), wid), 'wall')
  end do
  do i = 1, 50
    call ok(mpmc_sim_step(sim, 1.0e-4_c_double), 'step')
  end do
  call ok(mpmc_sim_get_kinetic_energy(sim, ke), 'kinetic energy')
  call MPI_Allreduce(ke, kemin, 1, MPI_DOUBLE_PRECISION, MPI_MIN, MPI_COMM_WORLD, ierr)
  call MPI_Allreduce(ke, kemax, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD, ierr)
  if (.not. (ke > 0.0_c_double .and. kemin == kemax)) then
    write (*, '(a,i0,a,es12.5,a,es12.5,a,es12.5)') 'FAILED: rank ', rank, &
      ': kinetic energy ', ke, ' expected > 0 and the same on every rank: min ', kemin, ', max ', kemax
    nfail = nfail + 1
  end if
  call ok(mpmc_sim_destroy(sim), 'destroy')
  call ok(mpmc_context_destroy(ctx), 'destroy context')
  call MPI_Allreduce(MPI_IN_PLACE, nfail, 1, MPI_INTEGER, MPI_SUM, MPI_COMM_WORLD, ierr)
  call MPI_Finalize(ierr)
  if (nfail > 0) stop 1

contains

  subroutine ok(code, what)
    integer(c_int), intent(in) :: code
    character(*), intent(in) :: what
    if (code /= MPMC_SUCCESS) then
      write (*, '(a,i0,a,a,a,i0,a,a)') 'FAILED: rank ', rank, ': ', what, ' returned ', code, ': ', &
        mpmc_context_last_error(ctx)
      nfail = nfail + 1
    end if
  end subroutine

  subroutine expect_int(what, expected, got)
    character(*), intent(in) :: what
    integer, intent(in) :: expected
    integer(c_int), intent(in) :: got
    if (expected /= got) then
      write (*, '(a,i0,a,a,a,i0,a,i0)') 'FAILED: rank ', rank, ': ', what, ': expected ', expected, &
        ', got ', got
      nfail = nfail + 1
    end if
  end subroutine
end program
