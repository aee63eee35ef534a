/* test_world.c: world, particle and distance-constraint API of the core. */
#include <stdint.h>
#include <string.h>

#include "test.h"
#include "wobble.h"

static wb_world *new_world(void)
{
    wb_world_def d = wb_world_default_def();
    return wb_world_create(&d);
}

TEST(world_def_defaults)
{
    wb_world_def d = wb_world_default_def();
    CHECK_EQ(d.gravity[0], 0);
    CHECK_NEAR(d.gravity[1], -9.81, 0);
    CHECK_EQ(d.gravity[2], 0);
    CHECK_NEAR(d.dt, 1.0 / 60.0, 0);
    CHECK_EQ(d.substeps, 10);
    CHECK_EQ(d.iterations, 1);
    CHECK_NEAR(d.damping, 0, 0);
    CHECK_EQ(d.solver, WB_SOLVER_GAUSS_SEIDEL);
    CHECK_NEAR(d.relaxation, 1, 0);
    CHECK_EQ(d.threads, 1);
    CHECK(wb_world_def_check(&d) == NULL);

    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_world_def g = wb_world_get_def(w);
    CHECK(memcmp(&g, &d, sizeof g) == 0);
    CHECK_EQ(wb_particle_count(w), 0);
    CHECK_EQ(wb_distance_count(w), 0);
    CHECK_EQ(wb_collider_count(w), 0);
    CHECK_NEAR(wb_world_time(w), 0, 0);
    CHECK_EQ(wb_world_frame(w), 0);
    CHECK_EQ(wb_world_warnings(w), 0);
    CHECK(strcmp(wb_world_last_warning(w), "") == 0);
    wb_real mn[3], mx[3];
    CHECK(!wb_world_bounds(w, mn, mx));
    wb_world_destroy(w);
    wb_world_destroy(NULL); /* documented as fine */
}

/* last in the table: under UBSan with -fno-sanitize-recover (make asan) a null
 * pointer passed to memcpy/memset aborts the whole binary */
TEST(world_step_empty)
{
    /* an empty world steps: time and frame advance, nothing else happens. Its
     * arrays are still NULL, so the step must not hand them to memcpy/memset even
     * with a size of 0 (undefined behaviour in C11 7.24.1p2) */
    wb_world_def d = wb_world_default_def();
    wb_world *w = wb_world_create(&d);
    REQUIRE(w);
    wb_world_step(w);
    CHECK_EQ(wb_world_frame(w), 1);
    CHECK_NEAR(wb_world_time(w), 1.0 / 60.0, 0);
    CHECK_EQ(wb_world_warnings(w), 0);
    /* a world with particles but no constraints: the multipliers array is NULL */
    const wb_real p[3] = { 0, 0, 0 };
    wb_particle_add(w, p, NULL, 1, 0);
    wb_world_step(w);
    CHECK_EQ(wb_world_frame(w), 2);
    wb_world_destroy(w);
}

TEST(world_def_check_messages)
{
    /* every bad setting is rejected with a message naming the setting */
#define CASE(k, body) do { \
        wb_world_def d = wb_world_default_def(); body; \
        const char *e = wb_world_def_check(&d); \
        CHECK_HAS(e, k); \
    } while (0)
    CASE("gravity", d.gravity[1] = NAN);
    CASE("gravity", d.gravity[2] = INFINITY);
    CASE("dt", d.dt = 0);
    CASE("dt", d.dt = -1);
    CASE("dt", d.dt = NAN);
    CASE("dt", d.dt = INFINITY);
    CASE("dt", d.dt = 11);
    CASE("substeps", d.substeps = 0);
    CASE("substeps", d.substeps = WB_MAX_SUBSTEPS + 1);
    CASE("iterations", d.iterations = 0);
    CASE("iterations", d.iterations = WB_MAX_ITERATIONS + 1);
    CASE("damping", d.damping = -0.1);
    CASE("damping", d.damping = NAN);
    CASE("damping", d.damping = INFINITY);
    CASE("solver", d.solver = (wb_solver)7);
    CASE("relaxation", d.relaxation = 0);
    CASE("relaxation", d.relaxation = 2);
    CASE("relaxation", d.relaxation = NAN);
    CASE("threads", d.threads = 0);
    CASE("threads", d.threads = WB_MAX_THREADS + 1);
#undef CASE
    /* the edges of the ranges are accepted */
    wb_world_def d = wb_world_default_def();
    d.dt = 10; d.substeps = WB_MAX_SUBSTEPS; d.iterations = WB_MAX_ITERATIONS;
    d.threads = WB_MAX_THREADS; d.relaxation = 1.9; d.solver = WB_SOLVER_JACOBI;
    CHECK(wb_world_def_check(&d) == NULL);

    /* set_def rejects a bad def, says why and changes nothing */
    wb_world *w = new_world();
    REQUIRE(w);
    wb_world_def before = wb_world_get_def(w);
    wb_world_def bad = before;
    bad.substeps = 0;
    CHECK_EQ(wb_world_set_def(w, &bad), WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "substeps");
    wb_world_def after = wb_world_get_def(w);
    CHECK(memcmp(&after, &before, sizeof after) == 0);
    /* and accepts a good one */
    wb_world_def good = before;
    good.substeps = 3;
    good.gravity[0] = 1;
    CHECK_EQ(wb_world_set_def(w, &good), WB_OK);
    CHECK_EQ(wb_world_get_def(w).substeps, 3);
    CHECK_NEAR(wb_world_get_def(w).gravity[0], 1, 0);
    wb_world_destroy(w);
}

/* a type's check names what is at fault the way a binding or a reader needs it: the key
 * of an option (and its reason alone), or the particle (0-based corner), or the particles
 * together; the add refuses exactly what the check refuses */
TEST(constraint_check_faults)
{
    const wb_real x[15] = { 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 2, 0, 0 };
    wb_distance_def dd = wb_distance_default_def();
    wb_fault f = wb_distance_check(5, x, 0, 1, &dd);
    CHECK(f.msg == NULL);
    f = wb_distance_check(5, x, 0, 0, &dd);
    CHECK(f.key == NULL); CHECK_EQ(f.corner, 1); CHECK_HAS(f.msg, "two distinct");
    f = wb_distance_check(5, x, 0, 7, &dd);
    CHECK_EQ(f.corner, 1); CHECK_HAS(f.msg, "out of range");
    dd.break_force = -1;
    f = wb_distance_check(5, x, 0, 1, &dd);
    REQUIRE(f.key); CHECK(strcmp(f.key, "break_force") == 0); CHECK(strcmp(f.why, "must be >= 0") == 0);
    CHECK(strcmp(f.msg, wb_distance_def_check(&dd)) == 0);
    const wb_real far[6] = { -1e200, 0, 0, 1e200, 0, 0 };
    dd = wb_distance_default_def();
    f = wb_distance_check(2, far, 0, 1, &dd);
    CHECK(f.key == NULL); CHECK_EQ(f.corner, -1); CHECK_HAS(f.msg, "too far apart");
    CHECK(wb_distance_check(2, NULL, 0, 1, &dd).msg == NULL); /* without positions: not checked */

    wb_bend_def bd = wb_bend_default_def();
    const int32_t ok[4] = { 0, 1, 2, 3 }, twice[4] = { 0, 1, 2, 1 }, flat[4] = { 0, 1, 2, 4 };
    CHECK(wb_bend_check(5, x, ok, &bd).msg == NULL);
    f = wb_bend_check(5, x, twice, &bd);
    CHECK(f.key == NULL); CHECK_EQ(f.corner, 3); CHECK_HAS(f.msg, "four distinct");
    f = wb_bend_check(5, x, flat, &bd);
    CHECK(f.key == NULL); CHECK_EQ(f.corner, -1); CHECK_HAS(f.msg, "degenerate");
    bd.rest = 4;
    f = wb_bend_check(5, x, ok, &bd);
    REQUIRE(f.key); CHECK(strcmp(f.key, "rest") == 0); CHECK_HAS(f.why, "[-pi, pi]");

    wb_tet_def td = wb_tet_default_def();
    CHECK(wb_tet_check(5, x, ok, &td).msg == NULL);
    CHECK_EQ(wb_tet_check(5, x, flat, &td).corner, -1);
    CHECK(wb_tet_check(5, NULL, flat, &td).msg == NULL);
    td.young = 1e15;
    f = wb_tet_check(5, x, ok, &td);
    REQUIRE(f.key); CHECK(strcmp(f.key, "young") == 0);

    wb_volume_def vd = wb_volume_default_def();
    vd.creep = -1;
    f = wb_volume_check(5, x, twice, &vd); /* the particles come first */
    CHECK(f.key == NULL); CHECK_EQ(f.corner, 3);
    f = wb_volume_check(5, x, ok, &vd);
    REQUIRE(f.key); CHECK(strcmp(f.key, "creep") == 0);

    wb_tether_def hd = wb_tether_default_def();
    hd.has_length = true; hd.length = -1;
    f = wb_tether_check(5, x, 0, 1, &hd);
    REQUIRE(f.key); CHECK(strcmp(f.key, "length") == 0);

    wb_shape_match_def sd = wb_shape_match_default_def();
    sd.stiffness = 2;
    f = wb_shape_match_def_fault(&sd);
    REQUIRE(f.key); CHECK(strcmp(f.key, "stiffness") == 0); CHECK(strcmp(f.why, "must be in [0, 1]") == 0);
    wb_pressure_def pd = wb_pressure_default_def();
    pd.pressure = 0;
    f = wb_pressure_def_fault(&pd);
    REQUIRE(f.key); CHECK(strcmp(f.key, "pressure") == 0);
    /* attachments and grabs: their compliance (m/N), finite and >= 0 */
    wb_fault (*const point_faults[2])(wb_real) = { wb_attach_def_fault, wb_grab_def_fault };
    for (int k = 0; k < 2; k++) {
        CHECK(point_faults[k](0).msg == NULL);
        CHECK(point_faults[k](1e-3).msg == NULL);
        f = point_faults[k](-1e-9);
        REQUIRE(f.key); CHECK(strcmp(f.key, "compliance") == 0); CHECK(strcmp(f.why, "must be >= 0 (m/N)") == 0);
        CHECK(point_faults[k](NAN).msg != NULL);
        CHECK(point_faults[k](INFINITY).msg != NULL);
    }

    /* the add refuses what the check refuses, with its message */
    wb_world *w = new_world();
    REQUIRE(w);
    const wb_real v0[3] = { 0, 0, 0 };
    for (int i = 0; i < 5; i++) wb_particle_add(w, &x[3 * i], v0, 1, 0.01);
    wb_status st = WB_OK;
    bd = wb_bend_default_def();
    wb_bend_add(w, flat, &bd, &st);
    CHECK_EQ(st, WB_ERR_ARG); CHECK_HAS(wb_last_error(), "degenerate");
    CHECK_EQ(wb_bend_count(w), 0);
    wb_bend_add(w, ok, &bd, &st);
    CHECK_EQ(st, WB_OK); CHECK_EQ(wb_bend_count(w), 1);
    wb_collider_def cd = wb_collider_default_def(WB_SHAPE_SPHERE);
    const wb_collider_id c = wb_collider_add(w, &cd, &st);
    REQUIRE(st == WB_OK);
    wb_attach_collider(w, 0, c, -1, &st);
    CHECK_EQ(st, WB_ERR_ARG); CHECK_HAS(wb_last_error(), "compliance must be >= 0");
    wb_grab_add(w, 0, x, NAN, &st);
    CHECK_EQ(st, WB_ERR_ARG); CHECK_HAS(wb_last_error(), "compliance must be >= 0");
    CHECK_EQ(wb_attach_count(w), 0); CHECK_EQ(wb_grab_count(w), 0);
    wb_world_destroy(w);
}

TEST(distance_and_collider_def_check_messages)
{
    wb_distance_def d = wb_distance_default_def();
    CHECK(wb_distance_def_check(&d) == NULL);
    CHECK_NEAR(d.compliance, 0, 0);
    CHECK(d.rest < 0); /* rest = current length */
    CHECK_NEAR(d.break_strain, 0, 0);
    d.compliance = -1; CHECK_HAS(wb_distance_def_check(&d), "compliance"); d = wb_distance_default_def();
    d.damping = NAN; CHECK_HAS(wb_distance_def_check(&d), "damping"); d = wb_distance_default_def();
    d.rest = INFINITY; CHECK_HAS(wb_distance_def_check(&d), "rest"); d = wb_distance_default_def();
    d.yield = -1; CHECK_HAS(wb_distance_def_check(&d), "yield"); d = wb_distance_default_def();
    d.creep = -1; CHECK_HAS(wb_distance_def_check(&d), "creep"); d = wb_distance_default_def();
    d.break_strain = -1; CHECK_HAS(wb_distance_def_check(&d), "break_strain");

    for (int s = 0; s < WB_SHAPE_COUNT; s++) {
        wb_collider_def c = wb_collider_default_def((wb_shape)s);
        /* a mesh collider has no default mesh: its check says so */
        if (s == WB_SHAPE_MESH) CHECK_HAS(wb_collider_def_check(&c), "mesh");
        else CHECK(wb_collider_def_check(&c) == NULL);
    }
    wb_collider_def c = wb_collider_default_def(WB_SHAPE_SPHERE);
    c.radius = 0; CHECK_HAS(wb_collider_def_check(&c), "radius");
    c = wb_collider_default_def(WB_SHAPE_CAPSULE);
    c.radius = -1; CHECK_HAS(wb_collider_def_check(&c), "radius");
    c = wb_collider_default_def(WB_SHAPE_PLANE);
    c.normal[0] = c.normal[1] = c.normal[2] = 0; CHECK_HAS(wb_collider_def_check(&c), "normal");
    c = wb_collider_default_def(WB_SHAPE_BOX);
    c.half[2] = 0; CHECK_HAS(wb_collider_def_check(&c), "half");
    c = wb_collider_default_def(WB_SHAPE_BOX);
    c.rotation[0] = 0; CHECK_HAS(wb_collider_def_check(&c), "rotation");
    c = wb_collider_default_def(WB_SHAPE_PLANE);
    c.friction = -0.5; CHECK_HAS(wb_collider_def_check(&c), "friction");
    c = wb_collider_default_def(WB_SHAPE_PLANE);
    c.restitution = 1.5; CHECK_HAS(wb_collider_def_check(&c), "restitution");
    c = wb_collider_default_def(WB_SHAPE_PLANE);
    c.shape = WB_SHAPE_COUNT; CHECK_HAS(wb_collider_def_check(&c), "shape");

    /* a failing add says why and adds nothing */
    wb_world *w = new_world();
    REQUIRE(w);
    wb_status st = WB_OK;
    c = wb_collider_default_def(WB_SHAPE_SPHERE);
    c.radius = -2;
    wb_collider_id id = wb_collider_add(w, &c, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_EQ(id.index, 0);
    CHECK_EQ(id.gen, 0);
    CHECK(!wb_collider_valid(w, id));
    CHECK_HAS(wb_last_error(), "radius");
    CHECK_EQ(wb_collider_count(w), 0);
    wb_world_destroy(w);
}

TEST(particle_add_get_set)
{
    wb_world *w = new_world();
    REQUIRE(w);
    const wb_real p0[3] = { 1, 2, 3 }, v0[3] = { -1, 0.5, 4 };
    int32_t a = wb_particle_add(w, p0, v0, 2.5, 0.1);
    int32_t b = wb_particle_add(w, p0, NULL, 1, 0);
    CHECK_EQ(a, 0);
    CHECK_EQ(b, 1);
    CHECK_EQ(wb_particle_count(w), 2);
    wb_real x[3], v[3];
    wb_particle_position(w, a, x);
    wb_particle_velocity(w, a, v);
    for (int i = 0; i < 3; i++) { CHECK_NEAR(x[i], p0[i], 0); CHECK_NEAR(v[i], v0[i], 0); }
    wb_particle_velocity(w, b, v); /* NULL velocity = at rest */
    for (int i = 0; i < 3; i++) CHECK_NEAR(v[i], 0, 0);
    CHECK_NEAR(wb_particle_mass(w, a), 2.5, 1e-15);
    CHECK_NEAR(wb_particle_radius(w, a), 0.1, 0);
    CHECK_NEAR(wb_particle_radius(w, b), 0, 0);
    CHECK(!wb_particle_pinned(w, a));
    CHECK_NEAR(wb_particle_positions(w)[3 * b + 2], 3, 0);

    const wb_real p1[3] = { -5, 6, 7 }, v1[3] = { 0.25, 0.5, 0.75 };
    wb_particle_set_position(w, a, p1);
    wb_particle_set_velocity(w, b, v1);
    wb_particle_position(w, a, x);
    for (int i = 0; i < 3; i++) CHECK_NEAR(x[i], p1[i], 0);
    wb_particle_velocity(w, a, v); /* teleport leaves the velocity alone */
    for (int i = 0; i < 3; i++) CHECK_NEAR(v[i], v0[i], 0);
    wb_particle_velocity(w, b, v);
    for (int i = 0; i < 3; i++) CHECK_NEAR(v[i], v1[i], 0);
    wb_world_destroy(w);
}

TEST(particle_immovable_and_pin)
{
    wb_world *w = new_world();
    REQUIRE(w);
    const wb_real p0[3] = { 0, 1, 0 }, v0[3] = { 3, 3, 3 }, p1[3] = { 1, 1, 0 }, p2[3] = { 2, 1, 0 };
    /* mass 0: immovable, a velocity given or set is dropped */
    int32_t a = wb_particle_add(w, p0, v0, 0, 0.1);
    int32_t b = wb_particle_add(w, p1, NULL, 1, 0.1);
    int32_t c = wb_particle_add(w, p2, NULL, 1, 0.1);
    CHECK_NEAR(wb_particle_mass(w, a), 0, 0);
    wb_real v[3], x[3];
    wb_particle_velocity(w, a, v);
    CHECK_NEAR(v[0], 0, 0);
    wb_particle_set_velocity(w, a, v0);
    wb_particle_velocity(w, a, v);
    CHECK_NEAR(v[0], 0, 0);
    CHECK_NEAR(v[1], 0, 0);

    wb_particle_pin(w, b, NULL);
    CHECK(wb_particle_pinned(w, b));
    CHECK_NEAR(wb_particle_mass(w, b), 1, 0); /* "as created" */
    const wb_real p3[3] = { 5, 5, 5 };
    wb_particle_pin(w, c, p3); /* pin somewhere else: teleported there */
    for (int f = 0; f < 30; f++) wb_world_step(w);
    wb_particle_position(w, a, x);
    for (int i = 0; i < 3; i++) CHECK_NEAR(x[i], p0[i], 0);
    wb_particle_position(w, b, x);
    for (int i = 0; i < 3; i++) CHECK_NEAR(x[i], p1[i], 0);
    wb_particle_velocity(w, b, v);
    for (int i = 0; i < 3; i++) CHECK_NEAR(v[i], 0, 0);
    wb_particle_position(w, c, x);
    for (int i = 0; i < 3; i++) CHECK_NEAR(x[i], p3[i], 0);
    /* a pinned particle ignores set_velocity */
    wb_particle_set_velocity(w, b, v0);
    wb_particle_velocity(w, b, v);
    CHECK_NEAR(v[0], 0, 0);
    /* immovable and pinned particles carry no momentum or energy */
    wb_real pm[3], ke, pe;
    wb_world_momentum(w, pm);
    CHECK_NEAR(pm[0], 0, 0); CHECK_NEAR(pm[1], 0, 0); CHECK_NEAR(pm[2], 0, 0);
    wb_world_energy(w, &ke, &pe);
    CHECK_NEAR(ke, 0, 0);
    CHECK_NEAR(pe, 0, 0);

    /* unpinned: falls again under gravity, with its own mass */
    wb_particle_unpin(w, b);
    CHECK(!wb_particle_pinned(w, b));
    wb_world_step(w);
    wb_particle_position(w, b, x);
    CHECK(x[1] < p1[1]);
    wb_particle_velocity(w, b, v);
    CHECK(v[1] < 0);
    CHECK_NEAR(wb_particle_mass(w, b), 1, 0);
    wb_world_momentum(w, pm);
    CHECK_NEAR(pm[1], v[1], 0); /* only b moves, with mass 1 */
    wb_world_destroy(w);
}

TEST(distance_handles)
{
    wb_world *w = new_world();
    REQUIRE(w);
    wb_real p[3] = { 0, 0, 0 };
    for (int i = 0; i < 4; i++) { p[0] = i; wb_particle_add(w, p, NULL, 1, 0); }
    wb_distance_def def = wb_distance_default_def();
    wb_status st = WB_ERR_NOMEM;
    wb_distance_id c01 = wb_distance_add(w, 0, 1, &def, &st);
    CHECK_EQ(st, WB_OK);
    CHECK(wb_distance_valid(w, c01));
    def.rest = 2.5;
    def.compliance = 1e-3;
    wb_distance_id c12 = wb_distance_add(w, 1, 2, &def, &st);
    wb_distance_id c23 = wb_distance_add(w, 2, 3, &def, NULL); /* status may be NULL */
    CHECK(wb_distance_valid(w, c12) && wb_distance_valid(w, c23));
    CHECK_EQ(wb_distance_count(w), 3);
    CHECK_NEAR(wb_distance_rest(w, c01), 1, 0); /* rest < 0: current length */
    CHECK_NEAR(wb_distance_rest(w, c12), 2.5, 0);
    CHECK_NEAR(wb_distance_length(w, c12), 1, 0);
    CHECK(!wb_distance_broken(w, c12));
    int32_t a, b;
    wb_distance_particles(w, c23, &a, &b);
    CHECK_EQ(a, 2);
    CHECK_EQ(b, 3);
    CHECK_NEAR(wb_distance_force(w, c01), 0, 0); /* never stepped */

    /* iteration visits each live constraint once, in slot order */
    CHECK(wb_distance_at(w, 0).index == c01.index && wb_distance_at(w, 0).gen == c01.gen);
    CHECK(wb_distance_at(w, 2).index == c23.index);
    CHECK_EQ(wb_distance_at(w, 3).index, 0);

    /* remove: the handle goes stale */
    wb_distance_remove(w, c12);
    CHECK(!wb_distance_valid(w, c12));
    CHECK(wb_distance_valid(w, c01) && wb_distance_valid(w, c23));
    CHECK_EQ(wb_distance_count(w), 2);
    CHECK(wb_distance_at(w, 1).index == c23.index);

    /* the slot is reused with a new generation: the old handle stays stale */
    def = wb_distance_default_def();
    wb_distance_id c03 = wb_distance_add(w, 0, 3, &def, &st);
    CHECK_EQ(st, WB_OK);
    CHECK(wb_distance_valid(w, c03));
    CHECK_EQ(c03.index, c12.index);
    CHECK(c03.gen != c12.gen);
    CHECK(!wb_distance_valid(w, c12));
    CHECK_NEAR(wb_distance_rest(w, c03), 3, 1e-15);
    /* remove and re-add again: neither older handle revives */
    wb_distance_remove(w, c03);
    wb_distance_id c13 = wb_distance_add(w, 1, 3, &def, &st);
    CHECK_EQ(c13.index, c12.index);
    CHECK(!wb_distance_valid(w, c12));
    CHECK(!wb_distance_valid(w, c03));
    CHECK(wb_distance_valid(w, c13));
    CHECK_EQ(wb_distance_count(w), 3);

    /* invalid handles */
    wb_distance_id none = { 0, 0 }, far = { 1000, 1 }, even = { c01.index, c01.gen + 1 };
    CHECK(!wb_distance_valid(w, none));
    CHECK(!wb_distance_valid(w, far));
    CHECK(!wb_distance_valid(w, even));

    /* bad arguments: an error, a null handle, nothing added */
    uint64_t hash = wb_world_hash(w);
    wb_distance_id bad = wb_distance_add(w, 2, 2, &def, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_EQ(bad.index, 0);
    CHECK_HAS(wb_last_error(), "distinct");
    bad = wb_distance_add(w, 0, 4, &def, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "range");
    bad = wb_distance_add(w, -1, 0, &def, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    def.compliance = -1;
    bad = wb_distance_add(w, 0, 1, &def, &st);
    CHECK_EQ(st, WB_ERR_ARG);
    CHECK_HAS(wb_last_error(), "compliance");
    CHECK_EQ(wb_distance_count(w), 3);
    CHECK(wb_world_hash(w) == hash);

    /* a step after the edits works on the live set only */
    wb_world_step(w);
    CHECK(wb_distance_valid(w, c13));
    CHECK(wb_distance_force(w, c01) >= 0);
    CHECK_EQ(wb_world_warnings(w), 0);
    wb_world_destroy(w);
}

TEST(collider_handles)
{
    wb_world *w = new_world();
    REQUIRE(w);
    wb_collider_def d = wb_collider_default_def(WB_SHAPE_SPHERE);
    wb_status st;
    wb_collider_id a = wb_collider_add(w, &d, &st);
    CHECK_EQ(st, WB_OK);
    wb_collider_id b = wb_collider_add(w, &d, &st);
    CHECK(wb_collider_valid(w, a) && wb_collider_valid(w, b));
    CHECK_EQ(wb_collider_count(w), 2);
    CHECK_EQ(wb_collider_shape(w, b), WB_SHAPE_SPHERE);
    wb_collider_remove(w, a);
    CHECK(!wb_collider_valid(w, a));
    CHECK_EQ(wb_collider_count(w), 1);
    CHECK(wb_collider_at(w, 0).index == b.index);
    d = wb_collider_default_def(WB_SHAPE_BOX);
    wb_collider_id c = wb_collider_add(w, &d, &st);
    CHECK_EQ(c.index, a.index); /* slot reused */
    CHECK(!wb_collider_valid(w, a));
    CHECK(wb_collider_valid(w, c));
    CHECK_EQ(wb_collider_shape(w, c), WB_SHAPE_BOX);
    wb_world_destroy(w);
}
