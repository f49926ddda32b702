! Fortran twin of the field-access tests: mpmc_sim_get_field hands out x(ncomp, np) that
! aliases the C storage (no copy) -- values written from Fortran are what the C library
! computes with, and values the C step writes appear through the same pointer.
program t111_fields_f
  use, intrinsic :: iso_c_binding, only: c_int, c_double, c_loc, c_associated, c_ptr
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use mpmc
  implicit none
  real(c_double), parameter :: rho = 1000.0_c_double, vol = 0.0625_c_double
  real(c_double), parameter :: dt = 1.0e-4_c_double, vx = 1.0_c_double, vy = -2.0_c_double
  type(mpmc_context) :: ctx
  type(mpmc_sim) :: sim
  integer(c_int) :: mat, first, ierr, q, sid, nsets
  real(c_double) :: x0(2, 4), ke
  real(c_double), pointer :: x(:, :), v(:, :), m(:), x1d(:), s(:, :)
  integer(c_int), pointer :: ids(:), idx(:), nodes(:, :)
  character(len=:), allocatable :: name
  type(c_ptr) :: px
  type(mpmc_stats) :: st
  integer :: nfail

  nfail = 0
  x0 = reshape([1.1_c_double, 1.2_c_double, 1.6_c_double, 1.3_c_double, &
                2.2_c_double, 2.4_c_double, 2.9_c_double, 1.8_c_double], [2, 4])
  call ok(mpmc_context_create(ctx), 'context')
  call ok(mpmc_sim_create(ctx, 2_c_int, sim), 'sim')
  call ok(mpmc_sim_set_grid(sim, [0.0_c_double, 0.0_c_double], [4.0_c_double, 4.0_c_double], &
    0.5_c_double), 'grid')
  call ok(mpmc_sim_add_material_hencky(sim, 1.0e6_c_double, 0.3_c_double, rho, mat), 'material')
  call ok(mpmc_sim_add_particles(sim, 4_c_int, x0, [vol, vol, vol, vol], mat, first), 'points')
  call expect_int('first', 0, first)

  ! positions: shape (dim, np), the values handed in
  call ok(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, x), 'get position')
  call expect_int('position rows', 2, size(x, 1))
  call expect_int('position columns', 4, size(x, 2))
  call expect_close('x(2, 3)', x0(2, 3), x(2, 3), 0.0_c_double)
  px = c_loc(x(1, 1))
  ! the rank-1 view starts at the same address and sees a write through the rank-2 view
  call ok(mpmc_sim_get_field(sim, MPMC_FIELD_POSITION, x1d), 'get position 1d')
  call expect_int('position 1d size', 8, size(x1d))
  call check(same_address(px, c_loc(x1d(1))), 'rank-1 and rank-2 views share the storage')
  x(1, 3) = 1.7_c_double
  call expect_close('x1d(5) after writing x(1, 3)', 1.7_c_double, x1d(5), 0.0_c_double)
  x(1, 3) = x0(1, 3)
  call ok(mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, x1d), 'restore position 1d')
  call check(.not. associated(x1d), 'restore nullifies the pointer')

  ! mass written by C: rho * volume
  call ok(mpmc_sim_get_field(sim, MPMC_FIELD_MASS, m), 'get mass')
  call expect_close('m(4)', rho*vol, m(4), 0.0_c_double)

  ! velocities written from Fortran are what C computes the kinetic energy from
  call ok(mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, v), 'get velocity')
  v(1, :) = vx
  v(2, :) = vy
  call ok(mpmc_sim_get_kinetic_energy(sim, ke), 'kinetic energy')
  call expect_close('kinetic energy', 0.5_c_double*4*rho*vol*(vx**2 + vy**2), ke, 1.0e-14_c_double)

  ! one step of a rigid translation: the step writes x through the pointer held across it;
  ! partition of unity moves every point by v dt and leaves the stress zero
  call ok(mpmc_sim_step(sim, dt), 'step')
  do q = 1, 4
    call expect_close('x(1, q) after a step', x0(1, q) + vx*dt, x(1, q), 1.0e-13_c_double)
    call expect_close('x(2, q) after a step', x0(2, q) + vy*dt, x(2, q), 1.0e-13_c_double)
  end do
  call ok(mpmc_sim_get_field(sim, MPMC_FIELD_STRESS, s), 'get stress')
  call expect_int('stress rows', 6, size(s, 1))
  call expect_close('max |stress| of a rigid translation', 0.0_c_double, maxval(abs(s)), 1.0e-6_c_double)
  ! the statistics as C fills them: one step of 4 points, its wall time split by phase
  call ok(mpmc_sim_get_stats(sim, st), 'stats')
  call expect_int('stats steps', 1, int(st%steps, c_int))
  call expect_int('stats particle steps', 4, int(st%particle_steps, c_int))
  call check(st%phase_seconds(MPMC_PHASE_P2G) > 0 .and. all(st%phase_seconds >= 0), &
    'phase times >= 0, P2G''s > 0')
  call expect_close('sum of the phase times', st%wall_seconds, sum(st%phase_seconds), &
    1.0e-9_c_double*st%wall_seconds)
  call check(mpmc_phase_name(MPMC_PHASE_G2P) == 'g2p', 'phase name of MPMC_PHASE_G2P: "'// &
    mpmc_phase_name(MPMC_PHASE_G2P)//'"')
  call ok(mpmc_sim_restore_field(sim, MPMC_FIELD_VELOCITY, v), 'restore velocity')
  call ok(mpmc_sim_restore_field(sim, MPMC_FIELD_POSITION, x), 'restore position')
  call check(.not. associated(x), 'restore nullifies the rank-2 pointer')

  ! material ids, borrowed
  call ok(mpmc_sim_get_material_ids(sim, ids), 'material ids')
  call expect_int('number of ids', 4, size(ids))
  call expect_int('ids(4)', mat, ids(4))

  ! a field the scene does not have: code and message
  ierr = mpmc_sim_get_field(sim, MPMC_FIELD_EPS_P, m)
  call expect_int('get eps_p without a plastic material', MPMC_ERR_STATE, ierr)
  call expect_has('message of eps_p', mpmc_context_last_error(ctx), "has no 'eps_p' field")
  call check(.not. associated(m), 'pointer null after a failed get')

  ! particle sets: names as Fortran strings, 0-based indices borrowed without a copy
  call ok(mpmc_sim_add_particle_set(sim, 'tip', [1_c_int, 3_c_int], sid), 'add set')
  call ok(mpmc_sim_get_num_particle_sets(sim, nsets), 'number of sets')
  call expect_int('number of sets', 1, nsets)
  call ok(mpmc_sim_find_particle_set(sim, 'tip', q), 'find set')
  call expect_int('found set id', sid, q)
  call ok(mpmc_sim_get_particle_set(sim, sid, name, idx), 'get set')
  call check(name == 'tip' .and. len(name) == 3, 'set name "tip", got "'//name//'"')
  call expect_int('set size', 2, size(idx))
  call expect_int('set idx(2)', 3, idx(2))
  ierr = mpmc_sim_add_particle_set(sim, 'bad', [7_c_int], sid)
  call expect_int('set with an index out of range', MPMC_ERR_ARG, ierr)
  call expect_has('message of the bad set', mpmc_context_last_error(ctx), 'idx[0] = 7 outside [0, 4)')

  ! node sets: ijk(dim, n), 0-based node coordinates, borrowed; a wall on one
  call ok(mpmc_sim_add_node_set(sim, 'base', reshape([0_c_int, 0_c_int, 1_c_int, 0_c_int], [2, 2]), sid), &
          'add node set')
  call ok(mpmc_sim_get_num_node_sets(sim, nsets), 'number of node sets')
  call expect_int('number of node sets', 1, nsets)
  call ok(mpmc_sim_find_node_set(sim, 'base', q), 'find node set')
  call expect_int('found node set id', sid, q)
  call ok(mpmc_sim_get_node_set(sim, sid, name, nodes), 'get node set')
  call check(name == 'base', 'node set name "base", got "'//name//'"')
  call expect_int('node set rows', 2, size(nodes, 1))
  call expect_int('node set size', 2, size(nodes, 2))
  call expect_int('node set ijk(1, 2)', 1, nodes(1, 2))
  call ok(mpmc_sim_add_wall_nodes(sim, sid, MPMC_WALL_FIXED, 0_c_int, -1_c_int, q), 'wall on a node set')
  ierr = mpmc_sim_find_node_set(sim, 'top', q)
  call expect_int('unknown node set', MPMC_ERR_ARG, ierr)
  call expect_has('message of the unknown node set', mpmc_context_last_error(ctx), "no node set named 'top'")

  ! sorting by cell: a point added at the lower left moves to the front, the ids follow the
  ! points and the set 'tip' (ids 1 and 3) is renumbered
  call ok(mpmc_sim_set_sort_interval(sim, 50_c_int), 'sort interval')
  call ok(mpmc_sim_get_sort_interval(sim, q), 'get sort interval')
  call expect_int('sort interval', 50, q)
  ierr = mpmc_sim_set_sort_interval(sim, -2_c_int)
  call expect_int('negative sort interval', MPMC_ERR_ARG, ierr)
  call expect_has('message of the negative interval', mpmc_context_last_error(ctx), 'sort interval = -2')
  call ok(mpmc_sim_add_particles(sim, 1_c_int, [0.6_c_double, 0.6_c_double], [vol], mat, first), 'fifth point')
  call expect_int('first of the fifth point', 4, first)
  call ok(mpmc_sim_sort_particles(sim), 'sort')
  call ok(mpmc_sim_get_particle_ids(sim, ids), 'particle ids')
  call expect_int('number of point ids', 5, size(ids))
  call check(all(ids == [4, 0, 1, 2, 3]), 'ids after the sort [4, 0, 1, 2, 3]')
  call ok(mpmc_sim_get_field(sim, MPMC_FIELD_X0, x), 'get x0 after the sort')
  call expect_close('x0(1, 1) after the sort', 0.6_c_double, x(1, 1), 0.0_c_double)
  call expect_close('x0(2, 3) after the sort', x0(2, 2), x(2, 3), 0.0_c_double)
  call ok(mpmc_sim_restore_field(sim, MPMC_FIELD_X0, x), 'restore x0 after the sort')
  call ok(mpmc_sim_find_particle_set(sim, 'tip', sid), 'find set after the sort')
  call ok(mpmc_sim_get_particle_set(sim, sid, name, idx), 'get set after the sort')
  call check(all(idx == [2, 4]), 'set tip renumbered to [2, 4]')

  deallocate (name) ! main-program variables are not freed automatically
  call ok(mpmc_sim_destroy(sim), 'destroy sim')

  ! a water table and the geostatic state from Fortran: a Mohr-Coulomb column of two points
  ! (E nu rho c phi psi c_r phi_r psi_r eta sigma_t rho_sat; NaN takes a default), the
  ! phreatic line at 3 m: the point at 1 m below it weighs rho_sat and carries
  ! p = 9810 * 2 Pa, the point at 3.5 m weighs rho and carries none
  call ok(mpmc_sim_create(ctx, 2_c_int, sim), 'water sim')
  call ok(mpmc_sim_set_grid(sim, [0.0_c_double, 0.0_c_double], [4.0_c_double, 4.0_c_double], &
    0.5_c_double), 'water grid')
  call ok(mpmc_sim_add_material(sim, 'mohr_coulomb', [1.0e7_c_double, 0.3_c_double, 1800.0_c_double, &
    1.0e4_c_double, 30.0_c_double, 0.0_c_double, ieee_value(1.0_c_double, ieee_quiet_nan), &
    ieee_value(1.0_c_double, ieee_quiet_nan), ieee_value(1.0_c_double, ieee_quiet_nan), &
    0.0_c_double, ieee_value(1.0_c_double, ieee_quiet_nan), 2100.0_c_double], mat), 'water material')
  call ok(mpmc_sim_set_water_table(sim, 1_c_int, [0.0_c_double, 3.0_c_double], 9810.0_c_double), &
    'water table')
  call ok(mpmc_sim_add_particles(sim, 2_c_int, reshape([1.0_c_double, 1.0_c_double, 1.0_c_double, &
    3.5_c_double], [2, 2]), [vol, vol], mat, first), 'water points')
  call ok(mpmc_sim_set_gravity(sim, [0.0_c_double, -9.81_c_double]), 'water gravity')
  call ok(mpmc_sim_set_geostatic_stress(sim, 0.5_c_double), 'geostatic stress')
  call ok(mpmc_sim_get_field(sim, MPMC_FIELD_MASS, m), 'water mass')
  call expect_close('saturated mass', 2100.0_c_double*vol, m(1), 1.0e-14_c_double)
  call expect_close('dry mass', 1800.0_c_double*vol, m(2), 1.0e-14_c_double)
  call ok(mpmc_sim_get_field(sim, MPMC_FIELD_PORE_PRESSURE, x1d), 'pore pressure')
  call expect_close('pore pressure below', 2.0_c_double*9810.0_c_double, x1d(1), 1.0e-14_c_double)
  call expect_close('pore pressure above', 0.0_c_double, x1d(2), 0.0_c_double)
  call ok(mpmc_sim_get_field(sim, MPMC_FIELD_STRESS, s), 'geostatic stresses')
  call check(s(2, 1) < 0.0_c_double .and. s(2, 2) < 0.0_c_double, 'geostatic sigma_yy compressive')
  ! the top point: sigma_h = K0 sigma_v (dry, effective = total)
  call expect_close('geostatic sigma_xx = K0 sigma_yy', 0.5_c_double*s(2, 2), s(1, 2), 1.0e-12_c_double)
  call ok(mpmc_sim_destroy(sim), 'destroy water sim')
  call ok(mpmc_context_destroy(ctx), 'destroy context')
  if (nfail > 0) error stop 1

contains

  logical function same_address(a, b)
    use, intrinsic :: iso_c_binding, only: c_intptr_t
    type(c_ptr), intent(in) :: a, b
    same_address = c_associated(a, b)
  end function

  subroutine ok(ierr, what)
    integer(c_int), intent(in) :: ierr
    character(*), intent(in) :: what
    if (ierr /= MPMC_SUCCESS) then
      write (*, '(a,a,a,i0,a,a)') 'FAILED: ', what, ' returned ', ierr, ': ', mpmc_context_last_error(ctx)
      nfail = nfail + 1
    end if
  end subroutine

  subroutine check(cond, what)
    logical, intent(in) :: cond
    character(*), intent(in) :: what
    if (.not. cond) then
      write (*, '(a,a)') 'FAILED: ', what
      nfail = nfail + 1
    end if
  end subroutine

  subroutine expect_int(what, expected, got)
    character(*), intent(in) :: what
    integer, intent(in) :: expected, got
    if (expected /= got) then
      write (*, '(a,a,a,i0,a,i0)') 'FAILED: ', what, ': expected ', expected, ', got ', got
      nfail = nfail + 1
    end if
  end subroutine

  subroutine expect_close(what, expected, got, tol)
    character(*), intent(in) :: what
    real(c_double), intent(in) :: expected, got, tol
    if (.not. abs(got - expected) <= tol*max(1.0_c_double, abs(expected))) then
      write (*, '(a,a,a,es24.16,a,es24.16)') 'FAILED: ', what, ': expected ', expected, ', got ', got
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

end program t111_fields_f
