/* test_recheck.c: the contact list is complete at every substep (broadphase.c,
 * wb__contacts_recheck). A stiff cloth hung over the floor and let fall into a heap on
 * itself: its links yank particles farther within a frame than their velocity and
 * gravity carry them, past the reach the frame's list was made with; each substep then
 * finds the particle moved too far and makes the list again. Checked by brute force:
 * every touching pair that may touch is in the list, at every substep. */
#include <math.h>

#include "test.h"
#include "core/core.h"

static wb_world *heap(int n)
{
    wb_world_def d = wb_world_default_def();
    d.damping = 0.5;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_collider_def floor = wb_collider_default_def(WB_SHAPE_PLANE);
    v3_set(floor.normal, 0, 1, 0);
    floor.offset = 0;
    floor.friction = 0.8;
    wb_status st;
    wb_collider_add(w, &floor, &st);
    wb_cloth_def c = wb_cloth_default_def();
    v3_set(c.origin, -0.25, 0, 0);
    c.size[0] = c.size[1] = 0.5;
    c.res[0] = c.res[1] = n;
    c.link.compliance = 1e-6;
    wb_body b;
    if (wb_cloth(w, &c, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    wb_body_set_contacts(w, b, true, true, 0.8);
    const wb_real r = w->m.radius[b.first];
    /* stood up in x-y, its lower edge two radii above the floor, rippled */
    for (int32_t i = b.first; i < b.first + b.count; i++) {
        wb_real p[3], v[3];
        wb_particle_position(w, i, p);
        const wb_real x = p[0], z = p[2];
        v3_set(p, x, z + 2 * r, 0.02 * sin(60 * z + 6 * x));
        v3_set(v, -1.2 * x * z, 0, 0.2 * sin(27 * z + 4.5 * x));
        wb_particle_set_position(w, i, p);
        wb_particle_set_velocity(w, i, v);
    }
    return w;
}

TEST(contact_list_complete_every_substep)
{
    int64_t missed[2], remakes[2];
    for (int on = 0; on < 2; on++) {
        wb_world *w = heap(32);
        REQUIRE(w);
        w->k.pc.brute = 1;
        w->k.pc.no_recheck = !on;
        for (int f = 0; f < 90; f++) wb_world_step(w);
        missed[on] = w->k.pc.missed;
        remakes[on] = w->k.pc.remakes;
        wb_world_destroy(w);
    }
    printf("# missed pairs without the check %lld, with it %lld (lists made again: %lld)\n",
           (long long)missed[0], (long long)missed[1], (long long)remakes[1]);
    CHECK(missed[0] > 0);  /* the scene does outrun the frame's reach */
    CHECK_EQ(missed[1], 0);
    CHECK(remakes[1] > 0);
}
