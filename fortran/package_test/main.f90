! Out-of-tree Fortran consumer of the installed package: one step of a free-falling point.
program consumer_f
  use, intrinsic :: iso_c_binding, only: c_int, c_double
  use mpmc
  implicit none
  type(mpmc_context) :: ctx
  type(mpmc_sim) :: sim
  integer(c_int) :: mat, first, major, minor, patch
  real(c_double), pointer :: v(:, :)
  if (mpmc_context_create(ctx) /= 0) error stop 1
  if (mpmc_sim_create(ctx, 2_c_int, sim) /= 0) error stop 1
  if (mpmc_sim_set_grid(sim, [0.0_c_double, 0.0_c_double], [1.0_c_double, 1.0_c_double], &
      0.25_c_double) /= 0 .or. mpmc_sim_set_gravity(sim, [0.0_c_double, -10.0_c_double]) /= 0 &
      .or. mpmc_sim_add_material_hencky(sim, 1.0e6_c_double, 0.3_c_double, 1000.0_c_double, mat) /= 0 &
      .or. mpmc_sim_add_particles(sim, 1_c_int, [0.5_c_double, 0.5_c_double], [0.01_c_double], &
      mat, first) /= 0 .or. mpmc_sim_step(sim, 1.0e-4_c_double) /= 0) then
    print '(a,a)', 'FAILED: ', mpmc_context_last_error(ctx)
    error stop 1
  end if
  if (mpmc_sim_get_field(sim, MPMC_FIELD_VELOCITY, v) /= 0) error stop 1
  if (abs(v(2, 1) + 1.0e-3_c_double) > 1.0e-12_c_double) then ! v_y = g dt
    print '(a,es24.16)', 'FAILED: expected v_y = -1e-3 after one step, got ', v(2, 1)
    error stop 1
  end if
  if (mpmc_version(major, minor, patch) /= 0) error stop 1
  print '(a,i0,a,i0,a,i0,a)', 'consumer_f: mpmc ', major, '.', minor, '.', patch, ' ok'
  if (mpmc_sim_destroy(sim) /= 0 .or. mpmc_context_destroy(ctx) /= 0) error stop 1
end program consumer_f
