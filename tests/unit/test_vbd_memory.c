/* test_vbd_memory.c: the VBD solver's arrays are charged to the world's memory budget
 * (def.memory) as every type's are, and a step whose VBD scratch the budget refuses fails
 * with WB_ERR_NOMEM and leaves the world as the frame found it, instead of taking memory
 * no budget sees. Two scenes: a cloth (the arrays prepare makes: adjacency, colouring,
 * multipliers) and a cloth lying on immovable particles (the contacts of the vertex
 * steps, sized inside the solve). Each is stepped once with no limit to learn what it
 * charges, then again in a fresh world whose limit is short of that by one byte. */
#include <stdint.h>
#include <string.h>

#include "core/core.h"
#include "test.h"

static wb_world *scene(wb_memory *mem, int on_pins)
{
    wb_world_def d = wb_world_default_def();
    d.memory = mem;
    d.solver = WB_SOLVER_VBD;
    d.substeps = 4;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_cloth_def c = wb_cloth_default_def();
    c.origin[0] = -1; c.origin[1] = 1; c.origin[2] = -1;
    c.size[0] = c.size[1] = 2;
    c.res[0] = c.res[1] = 24;
    wb_body b;
    if (wb_cloth(w, &c, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    if (on_pins) {
        /* an immovable particle just under each cloth particle of an 8 x 8 patch: pairs
         * with one immovable end, the contacts VBD takes into its vertex steps */
        const wb_real r = wb_particle_radius(w, b.first);
        for (int32_t i = 0; i < 8; i++)
            for (int32_t k = 0; k < 8; k++) {
                wb_real x[3];
                wb_particle_position(w, b.first + (8 + i) * c.res[0] + 8 + k, x);
                x[1] -= 2 * r;
                if (wb_particle_add(w, x, NULL, 0, r) < 0) { wb_world_destroy(w); return NULL; }
            }
    }
    return w;
}

TEST(vbd_memory_charged_and_refused)
{
    for (int on_pins = 0; on_pins < 2; on_pins++) {
        /* unlimited: what the step charges, and where it leads */
        wb_memory free_mem = { 0, 0 };
        wb_world *a = scene(&free_mem, on_pins);
        REQUIRE(a);
        const size_t built = free_mem.used;
        CHECK_EQ(wb_world_step(a), WB_OK);
        const size_t stepped = free_mem.used;
        /* (particles, links and bends are charged when made; the step adds VBD's own) */
        if (stepped <= built) test_fail(__FILE__, __LINE__, "scene %d: the VBD step charged nothing (%zu bytes before, %zu after)",
                                        on_pins, built, stepped);
        const uint64_t one = wb_world_hash(a);
        wb_world_destroy(a);
        CHECK_EQ(free_mem.used, 0); /* all given back */

        /* one byte short: the step fails and changes nothing */
        wb_memory mem = { 0, 0 };
        wb_world *b = scene(&mem, on_pins);
        REQUIRE(b);
        CHECK_EQ(mem.used, built);
        mem.limit = stepped - 1;
        const uint64_t before = wb_world_hash(b);
        CHECK_EQ(wb_world_step(b), WB_ERR_NOMEM);
        CHECK(mem.used <= mem.limit);
        CHECK_EQ(wb_world_frame(b), 0);
        CHECK_EQ(wb_world_hash(b), before);
        /* and with room, it steps as the world that never failed */
        mem.limit = stepped;
        CHECK_EQ(wb_world_step(b), WB_OK);
        CHECK_EQ(wb_world_hash(b), one);
        CHECK_EQ(mem.used, stepped);
        wb_world_destroy(b);
        CHECK_EQ(mem.used, 0);
    }
}

/* two cloths falling onto each other on a floor, joined at a corner by a link (one body: its
 * contacts with itself): hundreds of candidate pairs, none of which VBD takes into its
 * vertex steps or its bodies' moves (no immovable end, no other body), so its contact
 * scratch takes no memory: the world charges as much as with contacts off (it held arrays
 * for every candidate of the frame). Two free cloths would be two bodies moved together
 * with the pairs between them */
static wb_world *stacked(wb_memory *mem, bool contacts)
{
    wb_world_def d = wb_world_default_def();
    d.memory = mem;
    d.solver = WB_SOLVER_VBD;
    d.substeps = 4;
    d.contacts = contacts;
    wb_world *w = wb_world_create(&d);
    if (!w) return NULL;
    wb_collider_def floor = wb_collider_default_def(WB_SHAPE_PLANE);
    floor.offset = 0.9;
    wb_status st;
    wb_collider_add(w, &floor, &st);
    if (st != WB_OK) { wb_world_destroy(w); return NULL; }
    for (int s = 0; s < 2; s++) {
        wb_cloth_def c = wb_cloth_default_def();
        c.origin[0] = -1; c.origin[1] = 1 + 0.08 * s; c.origin[2] = -1;
        c.size[0] = c.size[1] = 2;
        c.res[0] = c.res[1] = 24;
        wb_body b;
        if (wb_cloth(w, &c, &b) != WB_OK) { wb_world_destroy(w); return NULL; }
    }
    const wb_distance_def link = wb_distance_default_def();
    wb_distance_add(w, 0, 24 * 24, &link, &st);
    if (st != WB_OK) { wb_world_destroy(w); return NULL; }
    return w;
}

TEST(vbd_memory_contact_scratch_only_for_its_pairs)
{
    wb_memory on = { 0, 0 }, off = { 0, 0 };
    wb_world *a = stacked(&on, true), *b = stacked(&off, false);
    REQUIRE(a && b);
    int touched = 0;
    for (int f = 0; f < 30; f++) {
        CHECK_EQ(wb_world_step(a), WB_OK);
        CHECK_EQ(wb_world_step(b), WB_OK);
        touched |= wb_world_stats(a).particle_contacts > 0;
    }
    CHECK(touched); /* the sheets met */
    CHECK_EQ(on.used, off.used);
    wb_world_destroy(a);
    wb_world_destroy(b);
}
