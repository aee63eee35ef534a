/* json.h: the JSON machinery shared by the particle-config reader (json.c), its value layer
 * (json_value.c), its writer (json_write.c) and the constraint types' files (json_NAME.c,
 * the jtype table): where each value of the text is, key paths, typed reads that fail with
 * "file:line:col: key.path: reason", and the writer's numbers. Private to io/json*.c (and
 * the input log, lua/input.c). */
#ifndef WB_IO_JSON_H
#define WB_IO_JSON_H

#include <cJSON.h>

#include "io.h"

/* the offset of every value of a (valid) JSON text, in document order */
typedef struct scan {
    const char *t, *p;
    int32_t n, cap;
    int32_t *voff;       /* (n) offset of each value, in document order */
    int32_t *koff;       /* (n) offset of its key, -1 outside objects */
    int oom;
} scan;

/* a key path, as a chain of links up to the root: "particles[3].position[1]" */
typedef struct kp {            /* a key path, as a chain up to the root */
    const struct kp *up;
    const char *key;           /* NULL: an array index */
    int64_t index;
} kp;

/* a reader: the file's name as shown, its text, the positions (NULL when unknown) and
 * where the message goes */
typedef struct rd {
    const char *shown, *text;
    const scan *pos;           /* NULL when positions are unknown */
    char *err;
    size_t errn;
} rd;

/* the memory budget of the read under way (json.c sets it; NULL: none): what its
 * transient allocations hold (chunks, malloc's header included), and whether one was
 * refused. realloc, malloc and free for everything a read allocates on its way (the
 * text, cJSON's nodes, the positions), charged to it */
typedef struct jbudget { wb_memory *mem; size_t held; bool over; } jbudget;
extern _Thread_local jbudget *jv_budget;
void *jb_realloc(void *p, size_t n);
void *jb_malloc(size_t n);
void jb_free(void *p);

/* positions: record every value of text (valid JSON) from s->p on, then number cJSON's
 * items in the same pre-order (their valueint holds the index) */
void jv_sk_value(scan *s, int32_t key);
void jv_number_items(cJSON *it, int32_t *k);
void jv_line_col(const char *t, int32_t off, int *line, int *col);

/* messages: "shown:line:col: key.path" of an item (its key when at_key), and failing
 * with it; every reader function returns 0, or -1 after jv_fail */
void jv_where_of(const rd *r, const cJSON *it, int at_key, const kp *path, char *buf, size_t n);
int jv_fail(rd *r, const cJSON *it, int at_key, const kp *path, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
int jv_missing(rd *r, const cJSON *obj, const kp *p, const char *key);
const char *jv_type_name(const cJSON *it);

/* typed values: the item must be of the type (numbers finite, integers in [lo, hi]) */
int jv_get_real(rd *r, const cJSON *it, const kp *p, wb_real *out);
int jv_get_int(rd *r, const cJSON *it, const kp *p, int64_t lo, int64_t hi, int64_t *out);
int jv_get_bool(rd *r, const cJSON *it, const kp *p, bool *out);
int jv_get_string(rd *r, const cJSON *it, const kp *p, const char **out);
int jv_get_array(rd *r, const cJSON *it, const kp *p, int64_t max, int32_t *count);
int jv_get_vec(rd *r, const cJSON *it, const kp *p, int n, wb_real *out); /* exactly n numbers */
/* an element's "particles": exactly k (2 or 4) indices of the np particles, into out;
 * `what` names the element in the messages ("a tet"). Whether they may repeat is the
 * type's check's to say (jv_fault) */
int jv_get_ids(rd *r, const cJSON *it, const kp *p, int32_t np, int k, const char *what, int32_t *out);
/* fail with what a type's check found (wb_fault; returns 0 when nothing): an option's at
 * its value (keys: the element's keys, f: their values, up: its path), the particles' at
 * their array, f[parts] (and there an option's whose value the file does not give) */
int jv_fault(rd *r, const wb_fault *ft, const kp *up, const char *const keys[], const cJSON *const f[], int parts);
/* an object whose keys are all in `keys` (NULL-terminated), none twice: found[i] = value */
int jv_get_object(rd *r, const cJSON *obj, const kp *p, const char *const keys[], const cJSON **found);

/* optional fields (f may be NULL: *out untouched); key names the field under up */
int jv_opt_real(rd *r, const cJSON *f, const kp *up, const char *key, wb_real *out);
int jv_opt_nonneg(rd *r, const cJSON *f, const kp *up, const char *key, wb_real *out);
int jv_opt_int(rd *r, const cJSON *f, const kp *up, const char *key, int64_t lo, int64_t hi, int64_t *out);
int jv_opt_vec(rd *r, const cJSON *f, const kp *up, const char *key, int n, wb_real *out);

/* writing (json_value.c): numbers as "%.17g", which round-trips every double through
 * strtod (cJSON's reader); a non-finite one is written as 0 and marks the output bad */
typedef struct jw_out {
    FILE *f;
    int bad;               /* a non-finite number was met */
    int nomem;             /* a scratch table could not be had */
    const char *head;      /* the opening of the array being written, not yet written (NULL: none) */
} jw_out;
void jw_num(jw_out *o, double x);
/* ', "key": x' */
void jw_key(jw_out *o, const char *key, double x);
void jw_vec(jw_out *o, const wb_real *v, int n);
/* n integers (u, or s when u is NULL), 24 a line, continued lines indented */
void jw_ints(FILE *f, const char *indent, const uint32_t *u, const int32_t *s, int32_t n);
/* before an element of an array: "\n" before the first (after o->head, once), ",\n" before
 * the others */
void jw_next(jw_out *o, int *first);
/* ", yield, creep" when either is set (files without stay as they were) */
void jw_plastic(jw_out *o, const wb_real yc[2]);

/* the file's "defaults": a particle's mass and radius (json.c), a link's options
 * (json_distance.c) */
typedef struct jdefaults {
    wb_real mass, radius;
    wb_distance_def link;
} jdefaults;

/* "generations": [...] of a slot table (its length checked), into gen; counts the live
 * (odd) ones (json_value.c) */
int jv_read_generations(rd *r, const cJSON *it, const kp *p, uint32_t *gen, int32_t *live);

/* a snapshot's slot table (of a type stored by slot: "distance_slots"), as scanned before
 * the image is made: the object, its arrays, and the image's slots and free slots */
typedef struct jslots {
    const cJSON *gen, *free;
    int32_t n, nfree;
} jslots;

/* A constraint type in a particle config: its reader and writer, in its own file
 * (json_NAME.c, beside core/NAME.c). Its elements are either an array of their own at the
 * root (key: "volumes") or entries of "constraints" with its "type" (entry: "bend").
 * - alloc: room in the image for n elements (NULL for distances: they fill the slots the
 *   image is made with, which the snapshot's "distance_slots" describe);
 * - read_item: the element at c (path p) into the image; *at: the type's own cursor, -1
 *   before its first. The array of its own is read after the particles, colliders,
 *   surfaces and rigid bodies; "constraints" after the particles;
 * - read: for a type that reads its own array otherwise (arr may be NULL: none), in place
 *   of alloc and read_item;
 * - write: w:save's elements, each after jw_next (first: none written yet in the array;
 *   returns whether still none). An array of its own is left out when it has none.
 * The table (json_types.c) is in the order w:save writes them and the reader reads them;
 * the root's keys and the entries' "type" names come from it */
typedef struct jtype {
    const char *key, *entry;
    wb_status (*alloc)(wb_image *g, int32_t n);
    int (*read_item)(rd *r, const cJSON *c, const kp *p, const jdefaults *d, wb_image *g, int32_t *at);
    int (*read)(rd *r, const cJSON *arr, wb_image *g);
    int (*write)(jw_out *o, const wb_image *g, int first);
    /* its options in the file's "defaults" (may be NULL: none): their keys, and the reader
     * of their values f (NULL where not given; p NULL: no "defaults"), which also sets
     * them when none is given */
    const char *const *default_keys;
    int (*read_defaults)(rd *r, const cJSON *const f[], const kp *p, jdefaults *d);
    /* a type stored by slot (the image's distance slots): its slot table in the snapshot
     * (may be NULL: none) at slots_key. scan_slots: its shape, before the image is made
     * (it: NULL when the file has none: then one slot per entry, nentries); read_slots:
     * its values into the image (after the image is made, before the entries); write_slots:
     * w:save's, after the clock */
    const char *slots_key;
    int (*scan_slots)(rd *r, const cJSON *it, const kp *p, int32_t nentries, jslots *s);
    int (*read_slots)(rd *r, const jslots *s, const kp *p, int32_t nentries, wb_image *g);
    void (*write_slots)(FILE *f, const wb_image *g);
} jtype;
#define JT_MAX 16 /* the table's room */
extern const jtype *const jtypes[];
extern const int njtypes;
/* each in its file: json_distance.c, json_bend.c, ... */
extern const jtype jt_distance, jt_bend, jt_volume, jt_tet, jt_shape_match, jt_pressure, jt_attach, jt_grab, jt_tether;
/* json_rigid.c: the "rigids" section (arr may be NULL) into the image */
int jr_read_rigids(rd *r, const cJSON *arr, wb_image *g);

#endif
