/* main.c: the table of unit tests and the runner.
 *
 *   build-ut/unit_tests            run every test
 *   build-ut/unit_tests NAME...    run the tests whose name contains one of NAME
 *
 * Output: "1..N", then "ok N - name" / "not ok N - name" (failed checks as
 * "#   file:line: ..." lines before it), and last exactly "N passed, N failed".
 * Exit status 1 when any test failed. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "test.h"

/* test_extreme.c: extreme but finite input */
#define EXTREME_TESTS(X)                                 \
    X(extreme_builders_refuse_overflowing_extents)       \
    X(extreme_builders_refuse_underflowing_mass_per_particle) \
    X(extreme_distance_refuses_overflowing_rest)         \
    X(extreme_dt_that_cannot_step_refused)               \
    X(extreme_compliance_over_h2_overflow_is_no_stiffness) \
    X(extreme_weld_tolerance_of_huge_and_tiny_boxes)     \
    X(extreme_normals_of_tiny_and_huge_triangles)        \
    X(extreme_from_mesh_refuses_overflowing_extent)      \
    X(extreme_kdtree_knn_except_bounded_under_ties)      \
    X(extreme_from_mesh_neighbours_with_ties)            \
    X(extreme_skin_neighbours_with_ties)                 \
    X(extreme_skin_refuses_vertices_out_of_range)        \
    X(extreme_damping_overflow_is_the_infinitely_damped_limit) \
    X(extreme_plastic_flow_of_a_tiny_rest_stays_finite)  \
    X(extreme_collider_derived_poses_finite)             \
    X(extreme_cluster_of_an_overflowing_box)

/* test_rigid.c: rigid bodies */
#define RIGID_TESTS(X)                                   \
    X(rigid_helpers_match_their_formulas)                \
    X(rigid_inertia_of_the_shapes)                       \
    X(rigid_slots_handles_and_budget)                    \
    X(rigid_nonfinite_frame_undone)                      \
    X(rigid_clone_same_hash_and_future)                  \
    X(rigid_pair_manifold_pushes_apart_by_inverse_mass)

/* test_contact.c: the particle-particle broad phase and contact rules */
#define CONTACT_TESTS(X)                                 \
    X(contact_broadphase_matches_brute_force)            \
    X(contact_broadphase_huge_and_clustered_input)       \
    X(contact_broadphase_bodies_fast_particles_and_threads) \
    X(contact_broadphase_kept_list_matches_fresh_search) \
    X(contact_broadphase_kept_list_mended_matches_fresh_search) \
    X(contact_builders_get_own_groups)                   \
    X(contact_self_collision_skips_rest_neighbours)      \
    X(contact_list_complete_every_substep)               \
    X(recheck_simd_bits)                                 \
    X(contact_list_gaps_same_bits)                       \
    X(contact_reference_simd_bits)                       \
    X(contact_rules_queue_same_keys)                     \
    X(contact_list_complete_with_reference_motion)       \
    X(contact_check_follows_reference_motion)            \
    X(contact_clone_keeps_groups)

/* test_tricontact.c: particle-triangle contacts */
#define TRICONTACT_TESTS(X)                              \
    X(tricontact_closest_point_regions)                  \
    X(tricontact_closest_matches_bvh)                    \
    X(tricontact_projection_conserves_momentum)          \
    X(tricontact_who_may_touch)

/* test_tribroad.c: the particle-triangle broad phase */
#define TRIBROAD_TESTS(X)                                \
    X(tribroad_matches_brute_force_heap)                 \
    X(tribroad_matches_brute_force_cloth)                \
    X(tribroad_matches_brute_force_sparse)               \
    X(tribroad_quick_answer_matches_search_over_frames)  \
    X(tribroad_quick_answer_at_the_edge_of_reach)        \
    X(tribroad_quick_answer_same_steps_as_search)

/* test_narrow.c: rigid shapes' contact manifolds */
#define NARROW_TESTS(X)                                  \
    X(narrow_sphere_sphere)                              \
    X(narrow_capsules)                                   \
    X(narrow_box_box_face)                               \
    X(narrow_box_box_reduced_and_face_preferred)         \
    X(narrow_box_box_edge)                               \
    X(narrow_plane)                                      \
    X(narrow_capsule_box)                                \
    X(narrow_sphere_box_regions)                         \
    X(narrow_mesh_icosahedron)                           \
    X(narrow_mesh_open_sheet)                            \
    X(narrow_swapped_order)                              \
    X(narrow_degenerate_input)                           \
    X(narrow_random_consistency)

/* test_pool.c: the thread pool */
#define POOL_TESTS(X)                                    \
    X(pool_for_runs_every_index_once)                    \
    X(pool_run_every_part_once)                          \
    X(pool_tiny_loops_stay_on_the_caller)                \
    X(pool_many_successive_jobs)                         \
    X(pool_destroyed_at_once_or_idle)                    \
    X(pool_nested_call_runs_inline)                      \
    X(pool_held_up_worker_then_solo)                     \
    X(pool_world_identical_for_1_2_3_threads)            \
    X(pool_without_threads_runs_inline)

/* test_fused.c: the next substep's prediction fused into the collision pass */
#define FUSED_TESTS(X)                                   \
    X(fused_predict_bits_one_plane)                      \
    X(fused_predict_bits_planes)                         \
    X(fused_predict_bits_mixed_colliders)                \
    X(fused_predict_bits_with_particle_contacts)         \
    X(fused_predict_bits_made_overlapping)               \
    X(fused_scan_finds_the_first_nonfinite_particle)     \
    X(fused_plane_simd_bits)                             \
    X(fused_plane_simd_scan_nonfinite)

/* every test, in the order they run: add a line here for each TEST() */
#define TEST_LIST(X)                             \
    X(world_def_defaults)                        \
    X(world_def_check_messages)                  \
    X(distance_and_collider_def_check_messages)  \
    X(constraint_check_faults)                   \
    X(particle_add_get_set)                      \
    X(particle_immovable_and_pin)                \
    X(distance_handles)                          \
    X(collider_handles)                          \
    X(builder_cloth_counts)                      \
    X(builder_cloth_shear_alternates)            \
    X(builder_rope_counts)                       \
    X(builder_lattice_counts)                    \
    X(builder_failure_changes_nothing)           \
    X(colour_batches_valid)                      \
    X(colour_broken_constraints_unpacked)        \
    X(colour_mirror_images_alike)                \
    X(colour_distances_made_with_the_first_link) \
    X(volume_tet_batches_valid)                  \
    X(volume_tet_threads_identical)              \
    X(bend_batches_valid)                        \
    X(bend_threads_identical)                    \
    X(bend_conserves_momentum)                   \
    X(bend_hinges_and_refusals)                  \
    X(bend_simd_bit_identical_to_scalar)         \
    X(bend_simd_threads_identical)               \
    X(collider_distance_plane)                   \
    X(collider_distance_sphere)                  \
    X(collider_distance_box_rotated)             \
    X(collider_distance_capsule)                 \
    X(collider_sweep_pushes_not_tunnels)         \
    X(collider_sweep_by_velocity_pushes)         \
    X(collider_resting_contact_no_bounce)        \
    X(free_fall_exact)                           \
    X(determinism_threads_gauss_seidel)          \
    X(determinism_threads_jacobi)                \
    X(nan_recovery_huge_velocity)                \
    X(subnormal_mass_refused)               \
    X(xpbd_static_force_balance)                 \
    X(world_damping_keeps_static_equilibrium)    \
    X(world_damping_terminal_velocity)           \
    X(step_never_writes_immovable)               \
    X(mesh_weld_stl_cube)                        \
    X(mesh_weld_tolerance_and_degenerates)       \
    X(mesh_create_rejects_bad_input)             \
    X(kdtree_matches_brute_force)                \
    X(mesh_cluster_target)                       \
    X(from_mesh_graph)                           \
    X(world_clone_exact)                         \
    X(rotation_extraction_matches_polar)         \
    X(rotation_extraction_warm_start)            \
    X(skin_rest_pose_reproduces_mesh)            \
    X(skin_weights_sum_to_one_and_fall_off)      \
    X(skin_rigid_motion_is_rigid)                \
    X(skin_follows_simulation)                   \
    X(skin_bad_definitions)                      \
    X(skin_follows_half_turns)                   \
    X(skin_rotation_independent_of_scale)        \
    X(skin_and_from_mesh_refuse_nonfinite_vertices) \
    X(world_step_empty)                          \
    X(step_interrupt_leaves_world_unchanged)     \
    X(force_reads_the_step_that_made_it)         \
    X(force_zero_after_an_undone_frame)          \
    X(types_multipliers_cleared_by_an_undone_frame) \
    X(types_counted_in_stats)                    \
    X(collider_huge_inputs_normalised)           \
    X(collider_absurd_velocity_recovers)         \
    X(hash_covers_collider_velocity_mass_radius) \
    X(memory_budget_shared_by_worlds)           \
    X(memory_budget_charges_worlds_and_threads) \
    X(memory_budget_charges_tets_and_volumes)   \
    X(distance_ids_match_distance_at)            \
    X(bvh_point_triangle_projection)             \
    X(bvh_closest_matches_brute_force)           \
    X(bvh_closed_and_open_and_sign)              \
    X(bvh_mesh_collider_memory_charged)          \
    CONTACT_TESTS(X)                             \
    TRICONTACT_TESTS(X)                          \
    TRIBROAD_TESTS(X)                            \
    EXTREME_TESTS(X)                             \
    X(tet_strain_volume_shape_and_shear)         \
    X(tet_simd_bit_identical_to_scalar)          \
    X(tet_threads_1_and_2_same_bits)             \
    X(blowup_slowed_and_reported_once)           \
    X(blowup_not_a_long_fall_nor_a_thrown_particle) \
    X(distance_compressed_link_regains_a_bounded_share) \
    X(attach_grab_forces_cleared_by_an_undone_frame) \
    X(attach_grab_clone_same_future)             \
    X(attach_grab_ids_and_memory)                \
    X(attach_skip_table_charged_and_lists)       \
    X(attach_grab_rigid_ids)                     \
    RIGID_TESTS(X)                               \
    NARROW_TESTS(X)                              \
    X(distance_simd_bit_identical_to_scalar)     \
    X(vbd_simd_bit_identical_to_scalar)          \
    X(vbd_memory_charged_and_refused)            \
    X(vbd_memory_contact_scratch_only_for_its_pairs) \
    X(momentum_simd_bit_identical_to_scalar)     \
    POOL_TESTS(X)                                \
    FUSED_TESTS(X)

#define DECLARE(name) TEST(name);
#define ENTRY(name) { #name, test_##name },
TEST_LIST(DECLARE)
static const test_case tests[] = { TEST_LIST(ENTRY) };

int test_failures;

void test_fail(const char *file, int line, const char *fmt, ...)
{
    test_failures++;
    va_list ap;
    va_start(ap, fmt);
    printf("#   %s:%d: ", file, line);
    vprintf(fmt, ap);
    printf("\n");
    va_end(ap);
    fflush(stdout);
}

static int selected(const char *name, int argc, char **argv)
{
    if (argc < 2) return 1;
    for (int i = 1; i < argc; i++)
        if (strstr(name, argv[i])) return 1;
    return 0;
}

int main(int argc, char **argv)
{
    const int n = (int)(sizeof tests / sizeof tests[0]);
    int total = 0;
    for (int i = 0; i < n; i++) total += selected(tests[i].name, argc, argv);
    printf("1..%d\n", total);
    int passed = 0, failed = 0, k = 0;
    for (int i = 0; i < n; i++) {
        if (!selected(tests[i].name, argc, argv)) continue;
        test_failures = 0;
        tests[i].fn();
        k++;
        if (test_failures == 0) {
            passed++;
            printf("ok %d - %s\n", k, tests[i].name);
        } else {
            failed++;
            printf("not ok %d - %s\n", k, tests[i].name);
        }
        fflush(stdout);
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
