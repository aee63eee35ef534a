/* json_rigid.c: the "rigids" section of a particle config:
 *
 *   "rigids": [ {"shape": "box", "half": [x,y,z], "mass": 1, "pos": [x,y,z],
 *                "rotation": [w,x,y,z], "vel": [..], "angular_velocity": [..],
 *                "friction": 0, "restitution": 0}, ... ]
 *
 * with "radius" for spheres and "a", "b", "radius" for capsules, as w:rigid{...} takes
 * them (a capsule's a and b about pos; its centre of mass is their midpoint). w:save
 * writes every slot with its "generation" (an even one: a removed body, no other key):
 * such an entry is the body exactly as saved (a and b about the centre, the rotation
 * unit), so that a reload has the same hash and the same future. */
#include <math.h>
#include <string.h>

#include "json.h"

int jr_read_rigids(rd *r, const cJSON *arr, wb_image *g)
{
    static const char *const keys[] = { "shape", "radius", "half", "a", "b", "mass", "pos", "rotation", "vel",
                                        "angular_velocity", "friction", "restitution", "generation", NULL };
    kp top = { NULL, "rigids", 0 };
    int32_t n = 0, i = 0;
    if (!arr) return 0;
    if (jv_get_array(r, arr, &top, WB_MAX_RIGIDS, &n)) return -1;
    if (wb_image_alloc_rigids(g, n) != WB_OK) return jv_fail(r, arr, 0, &top, "out of memory");
    for (const cJSON *c = arr->child; c; c = c->next, i++) {
        const cJSON *f[13];
        kp p = { &top, NULL, i };
        if (jv_get_object(r, c, &p, keys, f)) return -1;
        int64_t gen = 1;
        if (jv_opt_int(r, f[12], &p, "generation", 1, UINT32_MAX, &gen)) return -1;
        g->rb_gen[i] = (uint32_t)gen;
        if (!(gen & 1)) { /* a removed body's slot: nothing else, or the file was edited by mistake */
            for (int k = 0; k < 12; k++)
                if (f[k]) {
                    kp q = { &p, keys[k], 0 };
                    return jv_fail(r, f[k], 1, &q, "a removed body's slot (even generation) has no other key");
                }
            continue;
        }
        if (!f[0]) return jv_missing(r, c, &p, "shape");
        kp sp = { &p, "shape", 0 };
        const char *str;
        if (jv_get_string(r, f[0], &sp, &str)) return -1;
        int shape = -1;
        for (int k = 0; wb_shape_info_of((wb_shape)k); k++)
            if (!strcmp(str, wb_shape_info_of((wb_shape)k)->name)) shape = k;
        const wb_shape_info *in = shape >= 0 ? wb_shape_info_of((wb_shape)shape) : NULL;
        if (!in || !in->rigid_fields)
            return jv_fail(r, f[0], 0, &sp, "'%s' is not a rigid body shape (box, sphere or capsule)", str);
        /* a key of another shape is an error, as in w:rigid */
        for (int k = 1; k <= 4; k++)
            if (f[k] && !wb_shape_takes(in->rigid_fields, keys[k])) {
                kp q = { &p, keys[k], 0 };
                return jv_fail(r, f[k], 1, &q, "is not a key of a %s", in->name);
            }
        wb_rigid_def d = wb_rigid_default_def((wb_shape)shape);
        if (jv_opt_real(r, f[1], &p, "radius", &d.radius) || jv_opt_vec(r, f[2], &p, "half", 3, d.half) ||
            jv_opt_vec(r, f[3], &p, "a", 3, d.a) || jv_opt_vec(r, f[4], &p, "b", 3, d.b) ||
            jv_opt_real(r, f[5], &p, "mass", &d.mass) || jv_opt_vec(r, f[6], &p, "pos", 3, d.pos) ||
            jv_opt_vec(r, f[7], &p, "rotation", 4, d.rotation) || jv_opt_vec(r, f[8], &p, "vel", 3, d.vel) ||
            jv_opt_vec(r, f[9], &p, "angular_velocity", 3, d.angular_velocity) ||
            jv_opt_nonneg(r, f[10], &p, "friction", &d.friction) || jv_opt_real(r, f[11], &p, "restitution", &d.restitution))
            return -1;
        const char *e = wb_rigid_def_check(&d);
        if (e) return jv_fail(r, c, 0, &p, "%s", e);
        wb_image_rigid *o = &g->rb[i];
        if (f[12]) { /* as saved: raw */
            memset(o, 0, sizeof *o);
            o->shape = d.shape;
            /* the shape's own fields only (the others stay zero, as saved) */
            if (wb_shape_takes(in->rigid_fields, "radius")) o->radius = d.radius;
            if (wb_shape_takes(in->rigid_fields, "half")) memcpy(o->half, d.half, sizeof o->half);
            if (wb_shape_takes(in->rigid_fields, "a")) memcpy(o->a, d.a, sizeof o->a);
            if (wb_shape_takes(in->rigid_fields, "b")) memcpy(o->b, d.b, sizeof o->b);
            o->friction = d.friction;
            o->restitution = d.restitution;
            o->mass = d.mass;
            memcpy(o->x, d.pos, sizeof o->x);
            memcpy(o->q, d.rotation, sizeof o->q);
            memcpy(o->v, d.vel, sizeof o->v);
            memcpy(o->om, d.angular_velocity, sizeof o->om);
            /* here, not only in the snapshot's check, so that the error names this entry */
            const char *raw = wb_image_rigid_check(o);
            if (raw) return jv_fail(r, c, 0, &p, "%s (an entry with a generation is the body exactly as saved)", raw);
        } else if (wb_image_rigid_from_def(&d, o) != WB_OK) {
            return jv_fail(r, c, 0, &p, "%s", wb_last_error());
        }
    }
    return 0;
}
