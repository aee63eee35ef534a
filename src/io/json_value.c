/* json_value.c: the value layer of the JSON reader (json.h). cJSON gives the
 * position of a syntax error but keeps no positions in its tree, so a second pass over the
 * (valid) text records the offset of every value in document order, which is also the
 * order of a pre-order walk of cJSON's tree; errors then name the line and column of the
 * offending value or key, and its key path. Keys are case-sensitive; an unknown or
 * repeated key is an error (cJSON itself keeps duplicates). */
#include <ctype.h>
#include <malloc.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "json.h"

/* ---- the memory budget of a read ----------------------------------------------------------------- */
_Thread_local jbudget *jv_budget;

static size_t chunk(void *p) { return p ? malloc_usable_size(p) + sizeof(size_t) : 0; }

void *jb_realloc(void *p, size_t n)
{
    jbudget *b = jv_budget;
    if (!b || !b->mem) return realloc(p, n);
    wb_memory *m = b->mem;
    const size_t had = chunk(p), need = n + 2 * sizeof(size_t);
    if (m->limit && (need > m->limit || m->used - had > m->limit - need)) {
        b->over = true;
        return NULL;
    }
    void *q = realloc(p, n);
    if (!q) return NULL;
    m->used = m->used - had + chunk(q);
    b->held = b->held - had + chunk(q);
    return q;
}

void *jb_malloc(size_t n) { return jb_realloc(NULL, n); }

void jb_free(void *p)
{
    jbudget *b = jv_budget;
    if (b && b->mem && p) {
        b->mem->used -= chunk(p);
        b->held -= chunk(p);
    }
    free(p);
}

/* ---- the text and the positions of its values --------------------------------------------- */

static void sk_ws(scan *s)
{
    while (*s->p && (unsigned char)*s->p <= 32) s->p++;
}

static void sk_string(scan *s)
{
    s->p++;
    while (*s->p && *s->p != '"') s->p += (*s->p == '\\' && s->p[1]) ? 2 : 1;
    if (*s->p) s->p++;
}

/* the text is valid JSON (cJSON parsed it), so this only has to find where values start */
void jv_sk_value(scan *s, int32_t key)
{
    sk_ws(s);
    if (s->n == s->cap) {
        int32_t cap = s->cap ? 2 * s->cap : 1024;
        int32_t *v = jb_realloc(s->voff, sizeof *v * (size_t)cap), *k = v ? jb_realloc(s->koff, sizeof *k * (size_t)cap) : NULL;
        if (v) s->voff = v;
        if (!v || !k) { s->oom = 1; return; }
        s->koff = k;
        s->cap = cap;
    }
    s->voff[s->n] = (int32_t)(s->p - s->t);
    s->koff[s->n++] = key;
    const char open = *s->p;
    if (open == '{' || open == '[') {
        s->p++;
        for (;;) {
            sk_ws(s);
            if (*s->p == '}' || *s->p == ']' || !*s->p || s->oom) break;
            int32_t k = -1;
            if (open == '{') {
                k = (int32_t)(s->p - s->t);
                sk_string(s);
                sk_ws(s);
                if (*s->p == ':') s->p++;
            }
            jv_sk_value(s, k);
            sk_ws(s);
            if (*s->p == ',') s->p++;
        }
        if (*s->p) s->p++;
    } else if (open == '"') {
        sk_string(s);
    } else {
        while (*s->p && (isalnum((unsigned char)*s->p) || strchr("+-.", *s->p))) s->p++;
    }
}

/* every cJSON item's pre-order index goes into its valueint, a field this reader never uses
 * for anything else (numbers are read from valuedouble) */
void jv_number_items(cJSON *it, int32_t *k)
{
    for (; it; it = it->next) {
        it->valueint = (*k)++;
        jv_number_items(it->child, k);
    }
}

/* ---- errors with positions and key paths ----------------------------------------------------- */


static void kp_format(const kp *k, char *buf, size_t n)
{
    const kp *chain[64];
    int depth = 0;
    for (; k && depth < 64; k = k->up) chain[depth++] = k;
    size_t len = 0;
    buf[0] = '\0';
    for (int i = depth - 1; i >= 0 && len < n; i--) {
        if (chain[i]->key) len += (size_t)snprintf(buf + len, n - len, "%s%s", len ? "." : "", chain[i]->key);
        else len += (size_t)snprintf(buf + len, n - len, "[%lld]", (long long)chain[i]->index);
    }
}

void jv_line_col(const char *t, int32_t off, int *line, int *col)
{
    *line = 1;
    *col = 1;
    for (int32_t i = 0; i < off && t[i]; i++) {
        if (t[i] == '\n') { (*line)++; *col = 1; }
        else (*col)++;
    }
}

/* "shown:line:col: key.path" of the item (at its key when at_key, else at its value) */
void jv_where_of(const rd *r, const cJSON *it, int at_key, const kp *path, char *buf, size_t n)
{
    char keys[200], pos[48] = "";
    kp_format(path, keys, sizeof keys);
    if (it && r->pos && it->valueint >= 0 && it->valueint < r->pos->n) {
        int32_t off = r->pos->voff[it->valueint];
        if (at_key && r->pos->koff[it->valueint] >= 0) off = r->pos->koff[it->valueint];
        int line, col;
        jv_line_col(r->text, off, &line, &col);
        snprintf(pos, sizeof pos, ":%d:%d", line, col);
    }
    snprintf(buf, n, "%s%s%s%s", r->shown, pos, keys[0] ? ": " : "", keys);
}

int jv_fail(rd *r, const cJSON *it, int at_key, const kp *path, const char *fmt, ...)
{
    char msg[256], where[300];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    jv_where_of(r, it, at_key, path, where, sizeof where);
    snprintf(r->err, r->errn, "%s: %s", where, msg);
    return -1;
}

const char *jv_type_name(const cJSON *it)
{
    if (cJSON_IsObject(it)) return "object";
    if (cJSON_IsArray(it)) return "array";
    if (cJSON_IsString(it)) return "string";
    if (cJSON_IsNumber(it)) return "number";
    if (cJSON_IsBool(it)) return "boolean";
    return "null";
}

/* ---- typed values --------------------------------------------------------------------------- */
int jv_get_real(rd *r, const cJSON *it, const kp *p, wb_real *out)
{
    if (!cJSON_IsNumber(it)) return jv_fail(r, it, 0, p, "number expected, got %s", jv_type_name(it));
    if (!isfinite(it->valuedouble)) return jv_fail(r, it, 0, p, "number out of range");
    *out = (wb_real)it->valuedouble;
    return 0;
}

int jv_get_int(rd *r, const cJSON *it, const kp *p, int64_t lo, int64_t hi, int64_t *out)
{
    if (!cJSON_IsNumber(it)) return jv_fail(r, it, 0, p, "integer expected, got %s", jv_type_name(it));
    const double d = it->valuedouble;
    if (!(d == floor(d)) || !isfinite(d)) return jv_fail(r, it, 0, p, "integer expected, got %.17g", d);
    if (d < (double)lo || d > (double)hi)
        return jv_fail(r, it, 0, p, "%.17g out of range (%lld..%lld)", d, (long long)lo, (long long)hi);
    *out = (int64_t)d;
    return 0;
}

int jv_get_bool(rd *r, const cJSON *it, const kp *p, bool *out)
{
    if (!cJSON_IsBool(it)) return jv_fail(r, it, 0, p, "true or false expected, got %s", jv_type_name(it));
    *out = cJSON_IsTrue(it);
    return 0;
}

int jv_get_string(rd *r, const cJSON *it, const kp *p, const char **out)
{
    if (!cJSON_IsString(it)) return jv_fail(r, it, 0, p, "string expected, got %s", jv_type_name(it));
    *out = it->valuestring;
    return 0;
}

int jv_get_array(rd *r, const cJSON *it, const kp *p, int64_t max, int32_t *count)
{
    if (!cJSON_IsArray(it)) return jv_fail(r, it, 0, p, "array expected, got %s", jv_type_name(it));
    int64_t n = 0;
    for (const cJSON *c = it->child; c; c = c->next) n++;
    if (n > max) return jv_fail(r, it, 0, p, "too many entries (%lld, at most %lld)", (long long)n, (long long)max);
    *count = (int32_t)n;
    return 0;
}

int jv_get_ids(rd *r, const cJSON *it, const kp *p, int32_t np, int k, const char *what, int32_t *out)
{
    int32_t n = 0;
    if (jv_get_array(r, it, p, 16, &n)) return -1;
    if (n != k) return jv_fail(r, it, 0, p, "%s joins %d particles, got %d", what, k, n);
    int c = 0;
    for (const cJSON *e = it->child; e; e = e->next, c++) {
        kp q = { p, NULL, c };
        int64_t v = 0;
        if (np == 0) return jv_fail(r, e, 0, &q, "there are no particles");
        if (jv_get_int(r, e, &q, 0, np - 1, &v)) return -1;
        out[c] = (int32_t)v;
    }
    return 0;
}

int jv_fault(rd *r, const wb_fault *ft, const kp *up, const char *const keys[], const cJSON *const f[], int parts)
{
    if (!ft->msg) return 0;
    if (ft->key)
        for (int i = 0; keys[i]; i++)
            if (f[i] && strcmp(keys[i], ft->key) == 0) {
                kp q = { up, keys[i], 0 };
                return jv_fail(r, f[i], 0, &q, "%s", ft->why);
            }
    kp q = { up, keys[parts], 0 };
    return jv_fail(r, f[parts], 0, &q, "%s", ft->msg);
}

/* a slot table's generations (json.h) */
int jv_read_generations(rd *r, const cJSON *it, const kp *p, uint32_t *gen, int32_t *live)
{
    int32_t i = 0;
    *live = 0;
    for (const cJSON *c = it->child; c; c = c->next, i++) {
        kp e = { p, NULL, i };
        int64_t g = 0; /* (set when jv_get_int succeeds; -O3 cannot see it) */
        if (jv_get_int(r, c, &e, 0, UINT32_MAX, &g)) return -1;
        gen[i] = (uint32_t)g;
        *live += (int32_t)(g & 1);
    }
    return 0;
}

/* an array of exactly n finite numbers */
int jv_get_vec(rd *r, const cJSON *it, const kp *p, int n, wb_real *out)
{
    int32_t count = 0;
    if (!cJSON_IsArray(it)) return jv_fail(r, it, 0, p, "array of %d numbers expected, got %s", n, jv_type_name(it));
    if (jv_get_array(r, it, p, 16, &count) || count != n)
        return jv_fail(r, it, 0, p, "array of %d numbers expected, got %d value%s", n, count, count == 1 ? "" : "s");
    int i = 0;
    for (const cJSON *c = it->child; c; c = c->next, i++) {
        kp e = { p, NULL, i };
        if (jv_get_real(r, c, &e, &out[i])) return -1;
    }
    return 0;
}

/* the object's keys: each one of `keys` (NULL-terminated), none twice; found[i] = the value */
int jv_get_object(rd *r, const cJSON *obj, const kp *p, const char *const keys[], const cJSON **found)
{
    if (!cJSON_IsObject(obj)) return jv_fail(r, obj, 0, p, "object expected, got %s", jv_type_name(obj));
    int nk = 0;
    while (keys[nk]) found[nk++] = NULL;
    for (const cJSON *c = obj->child; c; c = c->next) {
        int i = 0;
        while (i < nk && strcmp(c->string, keys[i]) != 0) i++;
        kp here = { p, c->string, 0 };
        if (i == nk) {
            for (int j = 0; j < nk; j++)
                if (strcasecmp(c->string, keys[j]) == 0)
                    return jv_fail(r, c, 1, &here, "unknown key '%s' (keys are case-sensitive: '%s')", c->string, keys[j]);
            char list[400];
            size_t len = 0;
            for (int j = 0; j < nk && len < sizeof list; j++)
                len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", j ? ", " : "", keys[j]);
            return jv_fail(r, c, 1, &here, "unknown key '%s' (expected one of: %s)", c->string, list);
        }
        if (found[i]) {
            int line = 0, col = 0;
            if (r->pos) jv_line_col(r->text, r->pos->koff[found[i]->valueint], &line, &col);
            return jv_fail(r, c, 1, &here, "duplicate key '%s' (first at line %d, column %d)", c->string, line, col);
        }
        found[i] = c;
    }
    return 0;
}

int jv_missing(rd *r, const cJSON *obj, const kp *p, const char *key)
{
    return jv_fail(r, obj, 0, p, "missing key '%s'", key);
}

/* optional fields: absent leaves *out alone */
int jv_opt_real(rd *r, const cJSON *f, const kp *up, const char *key, wb_real *out)
{
    if (!f) return 0;
    kp p = { up, key, 0 };
    return jv_get_real(r, f, &p, out);
}

int jv_opt_nonneg(rd *r, const cJSON *f, const kp *up, const char *key, wb_real *out)
{
    if (!f) return 0;
    kp p = { up, key, 0 };
    if (jv_get_real(r, f, &p, out)) return -1;
    return *out < 0 ? jv_fail(r, f, 0, &p, "must be >= 0") : 0;
}

int jv_opt_int(rd *r, const cJSON *f, const kp *up, const char *key, int64_t lo, int64_t hi, int64_t *out)
{
    if (!f) return 0;
    kp p = { up, key, 0 };
    return jv_get_int(r, f, &p, lo, hi, out);
}

int jv_opt_vec(rd *r, const cJSON *f, const kp *up, const char *key, int n, wb_real *out)
{
    if (!f) return 0;
    kp p = { up, key, 0 };
    return jv_get_vec(r, f, &p, n, out);
}

/* ---- writing (json_write.c and the sections' writers) ------------------------------------ */
void jw_num(jw_out *o, double x)
{
    if (!isfinite(x)) { o->bad = 1; x = 0; }
    fprintf(o->f, "%.17g", x);
}

void jw_vec(jw_out *o, const wb_real *v, int n)
{
    fputc('[', o->f);
    for (int i = 0; i < n; i++) {
        if (i) fputs(", ", o->f);
        jw_num(o, (double)v[i]);
    }
    fputc(']', o->f);
}

void jw_ints(FILE *f, const char *indent, const uint32_t *u, const int32_t *s, int32_t n)
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

void jw_key(jw_out *o, const char *key, double x)
{
    fprintf(o->f, ", \"%s\": ", key);
    jw_num(o, x);
}

void jw_next(jw_out *o, int *first)
{
    if (*first && o->head) fputs(o->head, o->f);
    if (*first) o->head = NULL;
    fputs(*first ? "\n" : ",\n", o->f);
    *first = 0;
}

/* a volume's or a tet's plastic flow, only when it has one (files without stay as they were) */
void jw_plastic(jw_out *o, const wb_real yc[2])
{
    if (!(yc[0] > 0) && !(yc[1] > 0)) return;
    fputs(", \"yield\": ", o->f);
    jw_num(o, yc[0]);
    fputs(", \"creep\": ", o->f);
    jw_num(o, yc[1]);
}
