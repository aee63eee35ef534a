/* export.c: exports for other tools.
 *
 * PC2 (Blender's Mesh Cache modifier): a 32-byte header ("POINTCACHE2\0", version 1,
 * point count, start frame, sample rate, sample count), then float32 x y z per point per
 * sample, little-endian. The sample count in the header is patched after every sample,
 * so a run stopped early still leaves a readable cache of what was written.
 *
 * VTK (ParaView): a .pvd collection naming one XML PolyData (.vtp) file per frame. The
 * points are the particles, with point data velocity, speed, strain (the largest |strain|
 * of the particle's constraints), mass and pinned; the cells are the particles (vertices),
 * the constraints (lines) and the surfaces' triangles (polygons). ASCII, so the files are
 * diffable and need no base64 or compression library. */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"

/* ---- PC2 ---------------------------------------------------------------------------------- */
struct wbio_pc2 {
    FILE *f;
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
    p->f = fopen(path, "wb");
    if (!p->f) {
        snprintf(err, errn, "%s: %s", shown, strerror(errno));
        free(p->buf);
        free(p);
        return NULL;
    }
    unsigned char h[32];
    memcpy(h, "POINTCACHE2", 12);          /* 11 characters and the terminating zero */
    le32(h + 12, 1);                       /* file version */
    le32(h + 16, (uint32_t)npoints);
    le32(h + 20, float_bits((float)start_frame));
    le32(h + 24, float_bits((float)sample_rate)); /* frames per sample */
    le32(h + 28, 0);                       /* samples: patched as they come */
    if (fwrite(h, 1, sizeof h, p->f) != sizeof h) {
        snprintf(err, errn, "%s: %s", shown, strerror(errno));
        fclose(p->f);
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
    /* the count in the header follows every sample, so a run that stops without closing
     * (an error, a budget) still leaves a valid cache */
    unsigned char c[4];
    le32(c, (uint32_t)p->samples);
    if (fseek(p->f, 28, SEEK_SET) != 0 || fwrite(c, 1, 4, p->f) != 4 || fseek(p->f, 0, SEEK_END) != 0 || fflush(p->f) != 0) {
        snprintf(err, errn, "%s", strerror(errno ? errno : EIO));
        return -1;
    }
    return 0;
}

int32_t wbio_pc2_samples(const wbio_pc2 *p) { return p->samples; }

int wbio_pc2_close(wbio_pc2 *p, char *err, size_t errn)
{
    if (!p) return 0;
    int rc = fclose(p->f) != 0 ? -1 : 0;
    if (rc) snprintf(err, errn, "%s", strerror(errno ? errno : EIO));
    free(p->buf);
    free(p);
    return rc;
}

/* ---- VTK ------------------------------------------------------------------------------------- */
struct wbio_vtk {
    FILE *pvd;
    char *dir, *rel;       /* the .vtp folder, and as the .pvd names it */
    int32_t frames;
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
        v->dir = strdup(dir);
        v->rel = strdup(rel_dir);
    }
    if (!v || !v->dir || !v->rel) {
        snprintf(err, errn, "%s: out of memory", shown);
        if (v) { free(v->dir); free(v->rel); }
        free(v);
        return NULL;
    }
    v->pvd = fopen(pvd_path, "w");
    if (!v->pvd) {
        snprintf(err, errn, "%s: %s", shown, strerror(errno));
        free(v->dir);
        free(v->rel);
        free(v);
        return NULL;
    }
    fputs("<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
          "  <Collection>\n", v->pvd);
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

int wbio_vtk_write(wbio_vtk *v, const wb_world *w, char *err, size_t errn)
{
    char path[4200], name[64];
    const long long frame = (long long)wb_world_frame(w);
    snprintf(name, sizeof name, "frame_%06lld.vtp", frame);
    if (snprintf(path, sizeof path, "%s/%s", v->dir, name) >= (int)sizeof path) {
        snprintf(err, errn, "path too long");
        return -1;
    }
    FILE *f = fopen(path, "w");
    if (!f) {
        snprintf(err, errn, "%s: %s", path, strerror(errno));
        return -1;
    }
    int rc = wbio_write_vtp(f, w);
    if (fclose(f) != 0) rc = -1;
    if (rc) {
        snprintf(err, errn, "%s: %s", path, strerror(errno ? errno : EIO));
        return -1;
    }
    fprintf(v->pvd, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"", wb_world_time(w));
    xml_attr(v->pvd, v->rel);
    fprintf(v->pvd, "/%s\"/>\n", name);
    fflush(v->pvd);
    v->frames++;
    return 0;
}

int32_t wbio_vtk_frames(const wbio_vtk *v) { return v->frames; }

int wbio_vtk_close(wbio_vtk *v, char *err, size_t errn)
{
    if (!v) return 0;
    fputs("  </Collection>\n</VTKFile>\n", v->pvd);
    int rc = ferror(v->pvd) ? -1 : 0;
    if (fclose(v->pvd) != 0) rc = -1;
    if (rc) snprintf(err, errn, "%s", strerror(errno ? errno : EIO));
    free(v->dir);
    free(v->rel);
    free(v);
    return rc;
}
