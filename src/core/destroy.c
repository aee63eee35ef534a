/* destroy.c: a world's teardown. Every owner's arrays are freed here, each constraint
 * type's through its hook (ctype.h). A file of its own, above the types: they call the
 * world's leaf helpers (world.c), so a teardown there that called them back would close
 * a circle between the files. */
#include "ctype.h"
#include "bvh.h"
#include "rigid.h"
#include "vbd.h"

void wb_world_destroy(wb_world *w)
{
    if (!w) return;
    wb__rigids_free(w, w->rb);
    wb__vbd_destroy(w);
    wb__pool_destroy(w->pool);
    wb_model *m = &w->m;
    for (int32_t i = 0; i < m->nc; i++) wb__colmesh_free(m->c_shape[i].mesh); /* mesh colliders' copies */
    /* each type's arrays and what it charged to the budget */
    size_t charged = w->charged_self + m->charged + m->charged_mesh;
    for (int i = 0; i < wb__nctypes; i++) {
        const wb_ctype *t = wb__ctypes[i];
        if (t->charged) charged += t->charged(w);
        if (t->destroy) t->destroy(w);
    }
    if (m->def.memory) m->def.memory->used -= charged;
    wb_state *s = &w->s;
    wb_cache *k = &w->k;
    wb__contacts_destroy(w);
    wb__tricontacts_destroy(w);
    void *ptrs[] = { m->inv_mass, m->w, m->radius, m->pinned, m->group, m->cflags, m->cfric, m->x0, m->c_shape,
                     m->c_gen, m->surf_start, m->tri, s->x, s->x_prev, s->v, s->c_pose, k->dx, k->ncount, k->x_save,
                     k->v_save, k->c_sub, k->c_left, k->c_save, k->mc_body, k->mc_root, k->mc_acc, k->mc_pinned,
                     k->mc_end };
    for (size_t i = 0; i < sizeof ptrs / sizeof ptrs[0]; i++) free(ptrs[i]);
    free(w);
}
