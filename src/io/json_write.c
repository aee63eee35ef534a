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

#include "io.h"

typedef struct out {
    FILE *f;
    int bad;               /* a non-finite number was met */
    int nomem;             /* a scratch table could not be had */
} out;

static void num(out *o, double x)
{
    if (!isfinite(x)) { o->bad = 1; x = 0; }
    fprintf(o->f, "%.17g", x);
}

static void vec(out *o, const wb_real *v, int n)
{
    fputc('[', o->f);
    for (int i = 0; i < n; i++) {
        if (i) fputs(", ", o->f);
        num(o, (double)v[i]);
    }
    fputc(']', o->f);
}

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

static void ints(FILE *f, const char *indent, const uint32_t *u, const int32_t *s, int32_t n)
{
    fputc('[', f);
    for (int32_t i = 0; i < n; i++) {
        if (i) fputs(i % 24 ? ", " : ",\n", f);
        if (i && i % 24 == 0) fputs(indent, f);
        if (u) fprintf(f, "%u", u[i]);
        else fprintf(f, "%d", s[i]);
    }
    fputc(']', f);
}

static void write_snapshot(out *o, const wb_image *g)
{
    FILE *f = o->f;
    const wb_world_def *d = &g->def;
    fputs("  \"snapshot\": {\n    \"world\": {\"gravity\": ", f);
    vec(o, d->gravity, 3);
    fputs(", \"dt\": ", f);
    num(o, d->dt);
    fprintf(f, ", \"substeps\": %d, \"iterations\": %d, \"damping\": ", d->substeps, d->iterations);
    num(o, d->damping);
    fprintf(f, ", \"solver\": \"%s\", \"relaxation\": ", d->solver == WB_SOLVER_VBD ? "vbd" : d->solver == WB_SOLVER_JACOBI ? "jacobi" : "gauss-seidel");
    num(o, d->relaxation);
    fprintf(f, ", \"threads\": %d, \"contacts\": %s, \"max_depenetration\": ", d->threads, d->contacts ? "true" : "false");
    num(o, d->max_depenetration);
    fputs("},\n    \"time\": ", f);
    num(o, g->time);
    fprintf(f, ", \"frame\": %lld, \"warnings\": %lld, \"last_warning\": ", (long long)g->frame, (long long)g->warnings);
    str(f, g->last_warning);
    fputs(",\n    \"distance_slots\": {\"generations\": ", f);
    ints(f, "      ", g->d_gen, NULL, g->nd);
    fputs(", \"free\": ", f);
    ints(f, "      ", NULL, g->d_free, g->nfree);
    fputs("},\n    \"collider_slots\": {\"generations\": ", f);
    ints(f, "      ", g->c_gen, NULL, g->nc);
    fputs("}\n  },\n", f);
}

static void write_particles(out *o, const wb_image *g)
{
    FILE *f = o->f;
    fputs("  \"particles\": [", f);
    for (int32_t i = 0; i < g->np; i++) {
        fputs(i ? ",\n    {\"position\": " : "\n    {\"position\": ", f);
        vec(o, &g->x[3 * i], 3);
        fputs(", \"velocity\": ", f);
        vec(o, &g->v[3 * i], 3);
        /* mass for people, inv_mass for the exact restore */
        fputs(", \"mass\": ", f);
        num(o, g->inv_mass[i] > 0 ? 1 / g->inv_mass[i] : 0);
        fputs(", \"inv_mass\": ", f);
        num(o, g->inv_mass[i]);
        fputs(", \"radius\": ", f);
        num(o, g->radius[i]);
        fprintf(f, ", \"pinned\": %s, \"group\": %d, \"friction\": ", g->pinned[i] ? "true" : "false", g->group[i]);
        num(o, g->cfric[i]);
        fprintf(f, ", \"collide\": %s, \"self_collide\": %s, \"created_at\": ", (g->cflags[i] & 1) ? "true" : "false",
                (g->cflags[i] & 2) ? "true" : "false");
        vec(o, &g->x0[3 * i], 3);
        fputc('}', f);
    }
    fputs(g->np ? "\n  ],\n" : "],\n", f);
}

static void write_constraints(out *o, const wb_image *g)
{
    FILE *f = o->f;
    int first = 1;
    fputs("  \"constraints\": [", f);
    for (int32_t i = 0; i < g->nd; i++) {
        if (!(g->d_gen[i] & 1u)) continue;
        fprintf(f, "%s    {\"type\": \"distance\", \"particles\": [%d, %d], \"rest\": ", first ? "\n" : ",\n",
                g->d_ij[2 * i], g->d_ij[2 * i + 1]);
        first = 0;
        num(o, g->d_rest[i]);
        fputs(", \"compliance\": ", f);
        num(o, g->d_alpha[i]);
        fputs(", \"damping\": ", f);
        num(o, g->d_beta[i]);
        fputs(", \"yield\": ", f);
        num(o, g->d_yield[i]);
        fputs(", \"creep\": ", f);
        num(o, g->d_creep[i]);
        fputs(", \"break_strain\": ", f);
        num(o, g->d_break[i]);
        if (g->d_bforce[i] > 0) { /* only when set: configs without it read as before */
            fputs(", \"break_force\": ", f);
            num(o, g->d_bforce[i]);
        }
        fprintf(f, ", \"broken\": %s}", g->d_broken[i] ? "true" : "false");
    }
    for (int32_t i = 0; i < g->nb; i++) {
        const int32_t *p = &g->b_ij[4 * i];
        fprintf(f, "%s    {\"type\": \"bend\", \"particles\": [%d, %d, %d, %d], \"rest\": ", first ? "\n" : ",\n", p[0],
                p[1], p[2], p[3]);
        first = 0;
        num(o, g->b_rest[i]);
        fputs(", \"compliance\": ", f);
        num(o, g->b_alpha[i]);
        fputs(", \"damping\": ", f);
        num(o, g->b_beta[i]);
        if (g->b_btorque[i] > 0) { /* only when set: configs without it read as before */
            fputs(", \"break_torque\": ", f);
            num(o, g->b_btorque[i]);
        }
        if (g->b_broken[i]) fputs(", \"broken\": true", f);
        fputc('}', f);
    }
    fputs(first ? "],\n" : "\n  ],\n", f);
}

/* a volume's or a tet's plastic flow, only when it has one (files without stay as they were) */
static void plastic(out *o, const wb_real yc[2])
{
    if (!(yc[0] > 0) && !(yc[1] > 0)) return;
    fputs(", \"yield\": ", o->f);
    num(o, yc[0]);
    fputs(", \"creep\": ", o->f);
    num(o, yc[1]);
}

/* "volumes" (only when there are any: a config without stays as it was) */
static void write_volumes(out *o, const wb_image *g)
{
    FILE *f = o->f;
    if (g->nvol == 0) return;
    fputs("  \"volumes\": [", f);
    for (int32_t i = 0; i < g->nvol; i++) {
        const int32_t *p = &g->vol_ijkl[4 * i];
        fprintf(f, "%s    {\"particles\": [%d, %d, %d, %d], \"rest\": ", i ? ",\n" : "\n", p[0], p[1], p[2], p[3]);
        num(o, g->vol_rest[i]);
        fputs(", \"compliance\": ", f);
        num(o, g->vol_alpha[i]);
        plastic(o, &g->vol_plastic[2 * i]);
        fputc('}', f);
    }
    fputs("\n  ],\n", f);
}

/* "tets": Neo-Hookean tets with their rest state (json_material.c reads them) */
static void write_tets(out *o, const wb_image *g)
{
    FILE *f = o->f;
    if (g->ntet == 0) return;
    fputs("  \"tets\": [", f);
    for (int32_t i = 0; i < g->ntet; i++) {
        const int32_t *p = &g->tet_ijkl[4 * i];
        fprintf(f, "%s    {\"particles\": [%d, %d, %d, %d], \"young\": ", i ? ",\n" : "\n", p[0], p[1], p[2], p[3]);
        num(o, g->tet_young[i]);
        fputs(", \"poisson\": ", f);
        num(o, g->tet_poisson[i]);
        fputs(", \"rest_volume\": ", f);
        num(o, g->tet_v0[i]);
        fputs(", \"rest_inverse\": ", f);
        vec(o, &g->tet_dminv[9 * i], 9);
        plastic(o, &g->tet_plastic[2 * i]);
        fputc('}', f);
    }
    fputs("\n  ],\n", f);
}

/* shape-matching clusters and pressures (json_material.c reads them): only when present */
static void write_materials(out *o, const wb_image *g)
{
    FILE *f = o->f;
    const wb_image_smatch *s = &g->sm;
    for (int32_t k = 0; k < s->n; k++) {
        const int32_t a = s->start[k], b = s->start[k + 1];
        fputs(k ? ",\n    {\"particles\": " : "  \"shape_matches\": [\n    {\"particles\": ", f);
        ints(f, "      ", NULL, &s->ids[a], b - a);
        fputs(", \"stiffness\": ", f);
        num(o, s->stiff[k]);
        fputs(", \"yield\": ", f);
        num(o, s->yield[k]);
        fputs(", \"creep\": ", f);
        num(o, s->creep[k]);
        fputs(",\n     \"rest\": ", f);
        vec(o, &s->rest[3 * (int64_t)a], 3 * (b - a));
        fputs(", \"rotation\": ", f);
        vec(o, &s->q[4 * k], 4);
        fputc('}', f);
    }
    if (s->n) fputs("\n  ],\n", f);
    for (int32_t k = 0; k < g->pr.n; k++) {
        fprintf(f, "%s    {\"surface\": %d, \"pressure\": ", k ? ",\n" : "  \"pressures\": [\n", g->pr.surface[k]);
        num(o, g->pr.pressure[k]);
        fputs(", \"compliance\": ", f);
        num(o, g->pr.alpha[k]);
        fputs(", \"rest_volume\": ", f);
        num(o, g->pr.v0[k]);
        fputc('}', f);
    }
    if (g->pr.n) fputs("\n  ],\n", f);
}

/* "attachments" and "grabs" (json_attach.c reads them): only when present. An
 * attachment names its collider by its place among the written (live) colliders */
static void write_attach(out *o, const wb_image *g)
{
    FILE *f = o->f;
    const wb_image_attach *a = &g->att;
    /* slot -> its place among the live ones, once (a count per attachment is na x nc) */
    int32_t *rank = a->n ? malloc(sizeof *rank * (size_t)(g->nc > 0 ? g->nc : 1)) : NULL;
    if (a->n && !rank) {
        o->nomem = 1;
        return;
    }
    for (int32_t s = 0, r = 0; rank && s < g->nc; s++) {
        rank[s] = r;
        r += (int32_t)(g->c_gen[s] & 1u);
    }
    for (int32_t k = 0; k < a->n; k++) {
        /* a rigid body by its slot: w:save writes every slot of "rigids" */
        const int rigid = a->kind[k] == 1;
        fprintf(f, "%s    {\"particle\": %d, \"%s\": %d, \"point\": ", k ? ",\n" : "  \"attachments\": [\n",
                a->p[k], rigid ? "rigid" : "collider", rigid ? a->target[k] : rank[a->target[k]]);
        vec(o, &a->local[3 * k], 3);
        fputs(", \"compliance\": ", f);
        num(o, a->alpha[k]);
        fputc('}', f);
    }
    if (a->n) fputs("\n  ],\n", f);
    free(rank);
    const wb_image_grab *gr = &g->grab;
    for (int32_t k = 0; k < gr->n; k++) {
        /* a rigid body by its slot, as attachments name theirs */
        const int rigid = gr->kind[k] == 1;
        fprintf(f, "%s    {\"%s\": %d, ", k ? ",\n" : "  \"grabs\": [\n", rigid ? "rigid" : "particle", gr->p[k]);
        if (rigid) {
            fputs("\"at\": ", f);
            vec(o, &gr->local[3 * k], 3);
            fputs(", ", f);
        }
        fputs("\"target\": ", f);
        vec(o, &gr->target[3 * k], 3);
        fputs(", \"from\": ", f);
        vec(o, &gr->from[3 * k], 3);
        fputs(", \"compliance\": ", f);
        num(o, gr->alpha[k]);
        fputc('}', f);
    }
    if (gr->n) fputs("\n  ],\n", f);
}

static void write_colliders(out *o, const wb_image *g)
{
    static const char *const names[] = { "plane", "sphere", "box", "capsule", "mesh" };
    FILE *f = o->f;
    int first = 1;
    fputs("  \"colliders\": [", f);
    for (int32_t i = 0; i < g->nc; i++) {
        if (!(g->c_gen[i] & 1u)) continue;
        const wb_image_collider *c = &g->c[i];
        fprintf(f, "%s    {\"shape\": \"%s\", ", first ? "\n" : ",\n", names[c->shape]);
        first = 0;
        /* the shape in the collider's own frame: what the pose carries */
        switch (c->shape) {
        case WB_SHAPE_PLANE: fputs("\"normal\": ", f); vec(o, c->n, 3); break;
        case WB_SHAPE_SPHERE: fputs("\"radius\": ", f); num(o, c->radius); break;
        case WB_SHAPE_BOX: fputs("\"half\": ", f); vec(o, c->half, 3); break;
        case WB_SHAPE_MESH:
            /* its own copy, in its own frame with the scale applied: exact */
            fputs("\"vertices\": ", f);
            vec(o, c->mv, 3 * c->mnv);
            fputs(",\n     \"triangles\": [", f);
            for (int64_t k = 0; k < 3 * (int64_t)c->mnt; k++) fprintf(f, "%s%d", k ? ", " : "", (int)c->mt[k]);
            fputc(']', f);
            break;
        default:
            fputs("\"a\": ", f); vec(o, c->a, 3);
            fputs(", \"b\": ", f); vec(o, c->b, 3);
            fputs(", \"radius\": ", f); num(o, c->radius);
            break;
        }
        fputs(", \"friction\": ", f);
        num(o, c->friction);
        fputs(", \"restitution\": ", f);
        num(o, c->restitution);
        fputs(",\n     \"pose\": {\"position\": ", f);
        vec(o, c->p, 3);
        fputs(", \"rotation\": ", f);
        vec(o, c->q, 4);
        fputs(", \"start_position\": ", f);
        vec(o, c->p0, 3);
        fputs(", \"start_rotation\": ", f);
        vec(o, c->q0, 4);
        fputs(", \"velocity\": ", f);
        vec(o, c->v, 3);
        fputs(", \"angular_velocity\": ", f);
        vec(o, c->om, 3);
        fputs("}}", f);
    }
    fputs(first ? "],\n" : "\n  ],\n", f);
}

/* rigid bodies by slot, raw, with their generations (json_rigid.c reads them) */
static void write_rigids(out *o, const wb_image *g)
{
    static const char *const names[] = { "plane", "sphere", "box", "capsule", "mesh" };
    FILE *f = o->f;
    for (int32_t i = 0; i < g->nrb; i++) {
        const wb_image_rigid *b = &g->rb[i];
        fputs(i ? ",\n    {" : "  \"rigids\": [\n    {", f);
        if (!(g->rb_gen[i] & 1u)) { fprintf(f, "\"generation\": %u}", (unsigned)g->rb_gen[i]); continue; }
        fprintf(f, "\"shape\": \"%s\", ", names[b->shape]);
        if (b->shape == WB_SHAPE_BOX) { fputs("\"half\": ", f); vec(o, b->half, 3); }
        else { fputs("\"radius\": ", f); num(o, b->radius); }
        if (b->shape == WB_SHAPE_CAPSULE) {
            fputs(", \"a\": ", f); vec(o, b->a, 3);
            fputs(", \"b\": ", f); vec(o, b->b, 3);
        }
        fputs(", \"mass\": ", f); num(o, b->mass);
        fputs(", \"friction\": ", f); num(o, b->friction);
        fputs(", \"restitution\": ", f); num(o, b->restitution);
        fputs(",\n     \"pos\": ", f); vec(o, b->x, 3);
        fputs(", \"rotation\": ", f); vec(o, b->q, 4);
        fputs(", \"vel\": ", f); vec(o, b->v, 3);
        fputs(", \"angular_velocity\": ", f); vec(o, b->om, 3);
        fprintf(f, ", \"generation\": %u}", (unsigned)g->rb_gen[i]);
    }
    if (g->nrb) fputs("\n  ],\n", f);
}

static void write_surfaces(out *o, const wb_image *g)
{
    FILE *f = o->f;
    fputs("  \"surfaces\": [", f);
    for (int32_t s = 0; s < g->nsurf; s++) {
        const int32_t a = g->surf_start[s], b = g->surf_start[s + 1];
        fputs(s ? ",\n    {\"triangles\": " : "\n    {\"triangles\": ", f);
        ints(f, "      ", NULL, &g->tri[3 * (int64_t)a], 3 * (b - a));
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
    out o = { file.f, 0, 0 };
    setvbuf(o.f, NULL, _IOFBF, 1 << 20);
    fprintf(o.f, "{\n  \"format\": \"%s\",\n  \"version\": %d,\n  \"description\": \"wobble %s snapshot at frame %lld\",\n",
            WBIO_FORMAT, WBIO_VERSION, WB_VERSION, (long long)g.frame);
    write_snapshot(&o, &g);
    write_particles(&o, &g);
    write_constraints(&o, &g);
    write_volumes(&o, &g);
    write_tets(&o, &g);
    write_materials(&o, &g);
    write_attach(&o, &g);
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
