/* export.c: exports for other tools.
 *
 * PC2 (Blender's Mesh Cache modifier): a 32-byte header ("POINTCACHE2\0", version 1,
 * point count, start frame, sample rate, sample count), then float32 x y z per point per
 * sample, little-endian. The cache grows in a temporary beside its name (file.c), its
 * header's sample count patched after every sample, and takes the name when the
 * recording closes: an old cache of that name stays whole until then.
 *
 * VTK (ParaView): a .pvd collection naming one XML PolyData (.vtp) file per frame. Each
 * frame's .vtp is written whole, then the .pvd is written again whole, listing every
 * frame so far: whenever the run stops, the .pvd on disk is complete and names only
 * complete frames. The
 * points are the particles, with point data velocity, speed, strain (the largest |strain|
 * of the particle's constraints), mass and pinned; the cells are the particles (vertices),
 * the constraints (lines) and the surfaces' triangles (polygons). ASCII, so the files are
 * diffable and need no base64 or compression library. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io.h"

/* ---- PC2 ---------------------------------------------------------------------------------- */
struct wbio_pc2 {
    wbio_out out;
    FILE *f;               /* out's stream */
    int32_t n, samples;
    float *buf;            /* (n x 3) one sample, converted */
};

static void le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; i++) p[i] = (unsigned char)(v >> (8 * i));
}

static uint32_t float_bits(float x)
{
    uint32_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}

wbio_pc2 *wbio_pc2_open(const char *path, const char *shown, int32_t npoints, double start_frame, double sample_rate,
                        char *err, size_t errn)
{
    wbio_pc2 *p = calloc(1, sizeof *p);
    if (p) p->buf = malloc(sizeof *p->buf * 3 * (size_t)(npoints > 0 ? npoints : 1));
    if (!p || !p->buf) {
        snprintf(err, errn, "%s: out of memory", shown);
        if (p) free(p->buf);
        free(p);
        return NULL;
    }
    p->n = npoints;
    if (wbio_out_open(&p->out, AT_FDCWD, path, shown, err, errn)) {
        free(p->buf);
        free(p);
        return NULL;
    }
    p->f = p->out.f;
    unsigned char h[32];
    memcpy(h, "POINTCACHE2", 12);          /* 11 characters and the terminating zero */
    le32(h + 12, 1);                       /* file version */
    le32(h + 16, (uint32_t)npoints);
    le32(h + 20, float_bits((float)start_frame));
    le32(h + 24, float_bits((float)sample_rate)); /* frames per sample */
    le32(h + 28, 0);                       /* samples: patched as they come */
    if (fwrite(h, 1, sizeof h, p->f) != sizeof h) {
        snprintf(err, errn, "%s: %s", shown, strerror(errno));
        wbio_out_abort(&p->out);
        free(p->buf);
        free(p);
        return NULL;
    }
    return p;
}

int wbio_pc2_write(wbio_pc2 *p, const wb_real *pts, char *err, size_t errn)
{
    unsigned char *b = (unsigned char *)p->buf;
    for (int32_t i = 0; i < 3 * p->n; i++) le32(b + 4 * (size_t)i, float_bits((float)pts[i]));
    if (fwrite(b, 4, 3 * (size_t)p->n, p->f) != 3 * (size_t)p->n) {
        snprintf(err, errn, "%s", strerror(errno));
        return -1;
    }
    p->samples++;
    /* the count in the header follows every sample: the temporary is a valid cache of
     * what it holds at any moment */
    unsigned char c[4];
    le32(c, (uint32_t)p->samples);
    if (fseek(p->f, 28, SEEK_SET) != 0 || fwrite(c, 1, 4, p->f) != 4 || fseek(p->f, 0, SEEK_END) != 0 || fflush(p->f) != 0) {
        snprintf(err, errn, "%s", strerror(errno ? errno : EIO));
        return -1;
    }
    return 0;
}

int32_t wbio_pc2_samples(const wbio_pc2 *p) { return p->samples; }

int wbio_pc2_close(wbio_pc2 *p, int keep, char *err, size_t errn)
{
    if (!p) return 0;
    int rc = 0;
    if (!keep) wbio_out_abort(&p->out);
    else if (wbio_out_commit(&p->out, "", err, errn)) rc = -1;
    free(p->buf);
    free(p);
    return rc;
}

/* ---- VTK ------------------------------------------------------------------------------------- */
struct wbio_vtk {
    char *pvd;             /* the .pvd's path */
    int dir;               /* the .vtp folder, held open: every frame lands in it */
    char *rel;             /* that folder as the .pvd names it */
    int32_t frames, cap;
    int64_t *frame;        /* (frames) the world's frame of each .vtp, and its time */
    double *time;
};

static void vtk_list(FILE *f, const char *name, const char *type, int comps)
{
    if (comps > 1)
        fprintf(f, "        <DataArray type=\"%s\" Name=\"%s\" NumberOfComponents=\"%d\" format=\"ascii\">\n", type, name, comps);
    else
        fprintf(f, "        <DataArray type=\"%s\" Name=\"%s\" format=\"ascii\">\n", type, name);
}

int wbio_write_vtp(FILE *f, const wb_world *w)
{
    const int32_t np = wb_particle_count(w);
    const int32_t nd = wb_world_distance_pairs(w, NULL, NULL);
    int32_t *ij = malloc(sizeof *ij * 2 * (size_t)(nd > 0 ? nd : 1));
    wb_real *strain = malloc(sizeof *strain * (size_t)(nd > 0 ? nd : 1));
    wb_real *pstrain = calloc((size_t)(np > 0 ? np : 1), sizeof *pstrain);
    if (!ij || !strain || !pstrain) {
        free(ij); free(strain); free(pstrain);
        errno = ENOMEM;
        return -1;
    }
    wb_world_distance_pairs(w, ij, strain);
    for (int32_t i = 0; i < nd; i++)
        for (int k = 0; k < 2; k++)
            if (fabs(strain[i]) > pstrain[ij[2 * i + k]]) pstrain[ij[2 * i + k]] = fabs(strain[i]);
    int64_t ntri = 0;
    for (int32_t s = 0; s < wb_surface_count(w); s++) {
        int32_t n;
        wb_surface_triangles(w, s, &n);
        ntri += n;
    }
    fprintf(f, "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
               "  <PolyData>\n    <Piece NumberOfPoints=\"%d\" NumberOfVerts=\"%d\" NumberOfLines=\"%d\" "
               "NumberOfStrips=\"0\" NumberOfPolys=\"%lld\">\n      <Points>\n",
            np, np, nd, (long long)ntri);
    vtk_list(f, "position", "Float64", 3);
    const wb_real *x = wb_particle_positions(w);
    for (int32_t i = 0; i < np; i++) fprintf(f, "          %.9g %.9g %.9g\n", x[3 * i], x[3 * i + 1], x[3 * i + 2]);
    fputs("        </DataArray>\n      </Points>\n      <PointData Vectors=\"velocity\" Scalars=\"strain\">\n", f);
    vtk_list(f, "velocity", "Float64", 3);
    for (int32_t i = 0; i < np; i++) {
        wb_real v[3];
        wb_particle_velocity(w, i, v);
        fprintf(f, "          %.9g %.9g %.9g\n", v[0], v[1], v[2]);
    }
    fputs("        </DataArray>\n", f);
    vtk_list(f, "speed", "Float64", 1);
    for (int32_t i = 0; i < np; i++) {
        wb_real v[3];
        wb_particle_velocity(w, i, v);
        fprintf(f, "          %.9g\n", sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
    }
    fputs("        </DataArray>\n", f);
    vtk_list(f, "strain", "Float64", 1);
    for (int32_t i = 0; i < np; i++) fprintf(f, "          %.9g\n", pstrain[i]);
    fputs("        </DataArray>\n", f);
    vtk_list(f, "mass", "Float64", 1);
    for (int32_t i = 0; i < np; i++) fprintf(f, "          %.9g\n", wb_particle_mass(w, i));
    fputs("        </DataArray>\n", f);
    vtk_list(f, "pinned", "UInt8", 1);
    for (int32_t i = 0; i < np; i++) fprintf(f, "          %d\n", wb_particle_pinned(w, i) ? 1 : 0);
    fputs("        </DataArray>\n      </PointData>\n", f);
    /* cells: connectivity and running end offsets, per kind */
    fputs("      <Verts>\n", f);
    vtk_list(f, "connectivity", "Int32", 1);
    for (int32_t i = 0; i < np; i++) fprintf(f, "          %d\n", i);
    fputs("        </DataArray>\n", f);
    vtk_list(f, "offsets", "Int32", 1);
    for (int32_t i = 0; i < np; i++) fprintf(f, "          %d\n", i + 1);
    fputs("        </DataArray>\n      </Verts>\n      <Lines>\n", f);
    vtk_list(f, "connectivity", "Int32", 1);
    for (int32_t i = 0; i < nd; i++) fprintf(f, "          %d %d\n", ij[2 * i], ij[2 * i + 1]);
    fputs("        </DataArray>\n", f);
    vtk_list(f, "offsets", "Int32", 1);
    for (int32_t i = 0; i < nd; i++) fprintf(f, "          %d\n", 2 * (i + 1));
    fputs("        </DataArray>\n      </Lines>\n      <Polys>\n", f);
    vtk_list(f, "connectivity", "Int32", 1);
    for (int32_t s = 0; s < wb_surface_count(w); s++) {
        int32_t n;
        const int32_t *t = wb_surface_triangles(w, s, &n);
        for (int32_t i = 0; i < n; i++) fprintf(f, "          %d %d %d\n", t[3 * i], t[3 * i + 1], t[3 * i + 2]);
    }
    fputs("        </DataArray>\n", f);
    vtk_list(f, "offsets", "Int64", 1);
    for (int64_t i = 0; i < ntri; i++) fprintf(f, "          %lld\n", (long long)(3 * (i + 1)));
    fputs("        </DataArray>\n      </Polys>\n    </Piece>\n  </PolyData>\n</VTKFile>\n", f);
    free(ij);
    free(strain);
    free(pstrain);
    return ferror(f) ? -1 : 0;
}

wbio_vtk *wbio_vtk_open(const char *pvd_path, const char *dir, const char *rel_dir, const char *shown, char *err, size_t errn)
{
    wbio_vtk *v = calloc(1, sizeof *v);
    if (v) {
        v->dir = -1;
        v->pvd = strdup(pvd_path);
        v->rel = strdup(rel_dir);
    }
    if (!v || !v->pvd || !v->rel) {
        snprintf(err, errn, "%s: out of memory", shown);
        wbio_vtk_close(v, err, 0);
        return NULL;
    }
    /* the folder is checked by the caller; O_NOFOLLOW: it is not swapped for a link since */
    v->dir = open(dir, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (v->dir < 0) {
        snprintf(err, errn, "%s: %s: %s", shown, dir, strerror(errno));
        wbio_vtk_close(v, err, 0);
        return NULL;
    }
    return v;
}

/* text for a double-quoted XML attribute: & < > " ' as entities */
static void xml_attr(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        case '\'': fputs("&apos;", f); break;
        default: fputc(*s, f);
        }
    }
}

/* the .pvd, whole, naming the frames written so far */
static int write_pvd(const wbio_vtk *v, char *err, size_t errn)
{
    wbio_out o;
    if (wbio_out_open(&o, AT_FDCWD, v->pvd, v->pvd, err, errn)) return -1;
    fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
          "  <Collection>\n", o.f);
    for (int32_t i = 0; i < v->frames; i++) {
        fprintf(o.f, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"", v->time[i]);
        xml_attr(o.f, v->rel);
        fprintf(o.f, "/frame_%06lld.vtp\"/>\n", (long long)v->frame[i]);
    }
    fputs("  </Collection>\n</VTKFile>\n", o.f);
    return wbio_out_commit(&o, v->pvd, err, errn);
}

int wbio_vtk_write(wbio_vtk *v, const wb_world *w, char *err, size_t errn)
{
    char name[64];
    const long long frame = (long long)wb_world_frame(w);
    snprintf(name, sizeof name, "frame_%06lld.vtp", frame);
    if (v->frames == v->cap) {
        const int32_t cap = v->cap ? 2 * v->cap : 64;
        int64_t *f = realloc(v->frame, sizeof *f * (size_t)cap);
        if (f) v->frame = f;
        double *t = f ? realloc(v->time, sizeof *t * (size_t)cap) : NULL;
        if (t) v->time = t;
        if (!f || !t) {
            snprintf(err, errn, "out of memory");
            return -1;
        }
        v->cap = cap;
    }
    wbio_out o;
    char shown[PATH_MAX + 80];
    snprintf(shown, sizeof shown, "%s/%s", v->rel, name);
    if (wbio_out_open(&o, v->dir, name, shown, err, errn)) return -1;
    if (wbio_write_vtp(o.f, w)) o.failed = errno ? errno : EIO;
    if (wbio_out_commit(&o, shown, err, errn)) return -1;
    /* the frame's time as frame x dt: a running sum of dt drifts (frame 30 at 1/60 would
     * read 0.49999999999999994, and ParaView would show frame 31 for 0.5 s) */
    v->frame[v->frames] = frame;
    v->time[v->frames] = (double)frame * (double)wb_world_get_def(w).dt;
    v->frames++;
    if (write_pvd(v, err, errn)) {
        v->frames--;
        return -1;
    }
    return 0;
}

int32_t wbio_vtk_frames(const wbio_vtk *v) { return v->frames; }

int wbio_vtk_close(wbio_vtk *v, char *err, size_t errn)
{
    (void)err, (void)errn;
    if (!v) return 0;
    if (v->dir >= 0) close(v->dir);
    free(v->pvd);
    free(v->rel);
    free(v->frame);
    free(v->time);
    free(v);
    return 0;
}
