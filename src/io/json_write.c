/* json_write.c: w:save: the full state as a particle config plus a "snapshot" section
 * (settings, clock, slot tables), so that wobble.load restores it bit for bit. Doubles are
 * written with "%.17g", which round-trips every double through strtod (cJSON's reader). */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "json.h"

static void str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') fprintf(f, "\\%c", c);
        else if (c < 32) fprintf(f, "\\u%04x", c);
        else fputc(c, f);
    }
    fputc('"', f);
}

/* n numbers, 6 a line; NaN (not known) as null */
static void reals(jw_out *o, const wb_real *x, int32_t n)
{
    fputc('[', o->f);
    for (int32_t i = 0; i < n; i++) {
        if (i) fputs(i % 6 ? ", " : ",\n        ", o->f);
        if (isnan(x[i])) fputs("null", o->f);
        else jw_num(o, x[i]);
    }
    fputc(']', o->f);
}

static void write_snapshot(jw_out *o, const wb_image *g)
{
    FILE *f = o->f;
    const wb_world_def *d = &g->def;
    fputs("  \"snapshot\": {\n    \"world\": {\"gravity\": ", f);
    jw_vec(o, d->gravity, 3);
    jw_key(o, "dt", d->dt);
    fprintf(f, ", \"substeps\": %d, \"iterations\": %d, \"damping\": ", d->substeps, d->iterations);
    jw_num(o, d->damping);
    fprintf(f, ", \"solver\": \"%s\", \"relaxation\": ", d->solver == WB_SOLVER_VBD ? "vbd" : d->solver == WB_SOLVER_JACOBI ? "jacobi" : "gauss-seidel");
    jw_num(o, d->relaxation);
    fprintf(f, ", \"threads\": %d, \"contacts\": %s, \"max_depenetration\": ", d->threads, d->contacts ? "true" : "false");
    jw_num(o, d->max_depenetration);
    if (d->tolerance > 0) { /* (left out when off: files of worlds without it as they were) */
        jw_key(o, "tolerance", d->tolerance);
    }
    fputs("},\n    \"time\": ", f);
    jw_num(o, g->time);
    fprintf(f, ", \"frame\": %lld, \"warnings\": %lld, \"last_warning\": ", (long long)g->frame, (long long)g->warnings);
    str(f, g->last_warning);
    for (int k = 0; k < njtypes; k++)
        if (jtypes[k]->write_slots) jtypes[k]->write_slots(f, g);
    fputs(",\n    \"collider_slots\": {\"generations\": ", f);
    jw_ints(f, "      ", g->c_gen, NULL, g->nc);
    fputc('}', f);
    if (wb__image_has_vbd(g)) { /* (a VBD world that has stepped: others' files as they were) */
        fputs(",\n    \"vbd\": {\"multipliers\": ", f);
        reals(o, g->vbd_lam, g->vbd_nd);
        fputs(", \"errors\": ", f);
        reals(o, g->vbd_c0, g->vbd_nd);
        fputs(",\n      \"bend_multipliers\": ", f);
        reals(o, g->vbd_blam, g->vbd_nb);
        fputs(", \"bend_errors\": ", f);
        reals(o, g->vbd_bc0, g->vbd_nb);
        fputc('}', f);
    }
    fputs("\n  },\n", f);
}

static void write_particles(jw_out *o, const wb_image *g)
{
    FILE *f = o->f;
    fputs("  \"particles\": [", f);
    for (int32_t i = 0; i < g->np; i++) {
        fputs(i ? ",\n    {\"position\": " : "\n    {\"position\": ", f);
        jw_vec(o, &g->x[3 * i], 3);
        fputs(", \"velocity\": ", f);
        jw_vec(o, &g->v[3 * i], 3);
        /* mass for people, inv_mass for the exact restore */
        jw_key(o, "mass", g->inv_mass[i] > 0 ? 1 / g->inv_mass[i] : 0);
        jw_key(o, "inv_mass", g->inv_mass[i]);
        jw_key(o, "radius", g->radius[i]);
        fprintf(f, ", \"pinned\": %s, \"group\": %d, \"friction\": ", g->pinned[i] ? "true" : "false", g->group[i]);
        jw_num(o, g->cfric[i]);
        fprintf(f, ", \"collide\": %s, \"self_collide\": %s, \"created_at\": ", (g->cflags[i] & 1) ? "true" : "false",
                (g->cflags[i] & 2) ? "true" : "false");
        jw_vec(o, &g->x0[3 * i], 3);
        fputc('}', f);
    }
    fputs(g->np ? "\n  ],\n" : "],\n", f);
}

/* "constraints": the entries of every type that has them (jtypes), in the table's order */
static void write_constraints(jw_out *o, const wb_image *g)
{
    int first = 1;
    fputs("  \"constraints\": [", o->f);
    for (int i = 0; i < njtypes; i++)
        if (jtypes[i]->entry) first = jtypes[i]->write(o, g, first);
    fputs(first ? "],\n" : "\n  ],\n", o->f);
}

/* the types' arrays of their own, those that have elements (a file without stays as it was) */
static void write_sections(jw_out *o, const wb_image *g)
{
    for (int i = 0; i < njtypes; i++) {
        if (!jtypes[i]->key) continue;
        char head[64];
        snprintf(head, sizeof head, "  \"%s\": [", jtypes[i]->key);
        o->head = head;
        if (!jtypes[i]->write(o, g, 1)) fputs("\n  ],\n", o->f);
        o->head = NULL;
    }
}

/* one field of a shape (wobble.h's wb_shape_info lists) as "key": value: a collider's in its
 * own frame (c) or a rigid body's (b) */
static void write_field(jw_out *o, const char *k, size_t n, const wb_image_collider *c, const wb_image_rigid *b)
{
    FILE *f = o->f;
    fprintf(f, "\"%.*s\": ", (int)n, k);
#define IS(name) (n == sizeof name - 1 && !strncmp(k, name, n))
    if (IS("radius")) jw_num(o, c ? c->radius : b->radius);
    else if (IS("normal")) jw_vec(o, c->n, 3);
    else if (IS("half")) jw_vec(o, c ? c->half : b->half, 3);
    else if (IS("a")) jw_vec(o, c ? c->a : b->a, 3);
    else if (IS("b")) jw_vec(o, c ? c->b : b->b, 3);
    else if (IS("vertices")) jw_vec(o, c->mv, 3 * c->mnv); /* its own copy, scale applied: exact */
    else if (IS("triangles")) {
        fputc('[', f);
        for (int64_t i = 0; i < 3 * (int64_t)c->mnt; i++) fprintf(f, "%s%d", i ? ", " : "", (int)c->mt[i]);
        fputc(']', f);
    }
#undef IS
}

/* a shape's fields, in its list's order: ", " between them (a mesh's triangles on a line
 * of their own) */
static void write_fields(jw_out *o, const char *fields, const wb_image_collider *c, const wb_image_rigid *b)
{
    int first = 1;
    for (const char *p = fields; *p;) {
        while (*p == ' ') p++;
        const char *e = p;
        while (*e && *e != ' ') e++;
        if (e == p) break;
        if (!first) fputs(e - p == 9 && !strncmp(p, "triangles", 9) ? ",\n     " : ", ", o->f);
        write_field(o, p, (size_t)(e - p), c, b);
        first = 0;
        p = e;
    }
}

static void write_colliders(jw_out *o, const wb_image *g)
{
    FILE *f = o->f;
    int first = 1;
    fputs("  \"colliders\": [", f);
    for (int32_t i = 0; i < g->nc; i++) {
        if (!(g->c_gen[i] & 1u)) continue;
        const wb_image_collider *c = &g->c[i];
        fprintf(f, "%s    {\"shape\": \"%s\", ", first ? "\n" : ",\n", wb_shape_info_of(c->shape)->name);
        first = 0;
        /* the shape in the collider's own frame: what the pose carries */
        write_fields(o, wb_shape_info_of(c->shape)->own_fields, c, NULL);
        jw_key(o, "friction", c->friction);
        jw_key(o, "restitution", c->restitution);
        fputs(",\n     \"pose\": {\"position\": ", f);
        jw_vec(o, c->p, 3);
        fputs(", \"rotation\": ", f);
        jw_vec(o, c->q, 4);
        fputs(", \"start_position\": ", f);
        jw_vec(o, c->p0, 3);
        fputs(", \"start_rotation\": ", f);
        jw_vec(o, c->q0, 4);
        fputs(", \"velocity\": ", f);
        jw_vec(o, c->v, 3);
        fputs(", \"angular_velocity\": ", f);
        jw_vec(o, c->om, 3);
        fputs("}}", f);
    }
    fputs(first ? "],\n" : "\n  ],\n", f);
}

/* rigid bodies by slot, raw, with their generations (json_rigid.c reads them) */
static void write_rigids(jw_out *o, const wb_image *g)
{
    FILE *f = o->f;
    for (int32_t i = 0; i < g->nrb; i++) {
        const wb_image_rigid *b = &g->rb[i];
        fputs(i ? ",\n    {" : "  \"rigids\": [\n    {", f);
        if (!(g->rb_gen[i] & 1u)) { fprintf(f, "\"generation\": %u}", (unsigned)g->rb_gen[i]); continue; }
        const wb_shape_info *in = wb_shape_info_of(b->shape);
        fprintf(f, "\"shape\": \"%s\", ", in->name);
        write_fields(o, in->rigid_fields, NULL, b);
        fputs(", \"mass\": ", f); jw_num(o, b->mass);
        fputs(", \"friction\": ", f); jw_num(o, b->friction);
        fputs(", \"restitution\": ", f); jw_num(o, b->restitution);
        fputs(",\n     \"pos\": ", f); jw_vec(o, b->x, 3);
        fputs(", \"rotation\": ", f); jw_vec(o, b->q, 4);
        fputs(", \"vel\": ", f); jw_vec(o, b->v, 3);
        fputs(", \"angular_velocity\": ", f); jw_vec(o, b->om, 3);
        fprintf(f, ", \"generation\": %u}", (unsigned)g->rb_gen[i]);
    }
    if (g->nrb) fputs("\n  ],\n", f);
}

static void write_surfaces(jw_out *o, const wb_image *g)
{
    FILE *f = o->f;
    fputs("  \"surfaces\": [", f);
    for (int32_t s = 0; s < g->nsurf; s++) {
        const int32_t a = g->surf_start[s], b = g->surf_start[s + 1];
        fputs(s ? ",\n    {\"triangles\": " : "\n    {\"triangles\": ", f);
        jw_ints(f, "      ", NULL, &g->tri[3 * (int64_t)a], 3 * (b - a));
        fputc('}', f);
    }
    fputs(g->nsurf ? "\n  ]\n" : "]\n", f);
}

int wbio_write_snapshot(const wb_world *w, const char *path, const char *shown, char *err, size_t errn)
{
    wb_image g;
    if (wb_image_of(w, &g) != WB_OK) {
        snprintf(err, errn, "%s: out of memory", shown);
        return -1;
    }
    /* a temporary file beside the target, renamed over it once complete */
    wbio_out file;
    if (wbio_out_open(&file, AT_FDCWD, path, shown, err, errn)) {
        wb_image_free(&g);
        return -1;
    }
    jw_out o = { file.f, 0, 0, NULL };
    setvbuf(o.f, NULL, _IOFBF, 1 << 20);
    fprintf(o.f, "{\n  \"format\": \"%s\",\n  \"version\": %d,\n  \"description\": \"wobble %s snapshot at frame %lld\",\n",
            WBIO_FORMAT, WBIO_VERSION, WB_VERSION, (long long)g.frame);
    write_snapshot(&o, &g);
    write_particles(&o, &g);
    write_constraints(&o, &g);
    write_sections(&o, &g);
    write_rigids(&o, &g);
    write_colliders(&o, &g);
    write_surfaces(&o, &g);
    fputs("}\n", o.f);
    wb_image_free(&g);
    if (o.bad) {
        wbio_out_abort(&file);
        snprintf(err, errn, "%s: the state holds a non-finite number", shown);
        return -1;
    }
    if (o.nomem) file.failed = ENOMEM;
    if (wbio_out_commit(&file, shown, err, errn)) return -1;
    return 0;
}
