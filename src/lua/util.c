/* util.c: argument checking and small helpers shared by the binding files. */
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"
#include "io/io.h"
#include "render/render.h"

/* ---- the world userdata (its methods: world.c) ---- */
wbl_world *wbl_checkworld_ud(lua_State *L, int arg)
{
    return (wbl_world *)luaL_checkudata(L, arg, WBL_WORLD);
}

wb_world *wbl_checkworld(lua_State *L, int arg)
{
    wbl_world *ud = wbl_checkworld_ud(L, arg);
    if (!ud->w) luaL_error(L, "attempt to use a closed world");
    return ud->w;
}

/* ---- numbers ------------------------------------------------------------------- */
const char *wbl_numstr(char *buf, size_t n, double x)
{
    if (isnan(x)) snprintf(buf, n, "nan");
    else if (isinf(x)) snprintf(buf, n, x > 0 ? "inf" : "-inf");
    else snprintf(buf, n, "%.14g", x);
    return buf;
}

/* the value at idx as a finite number, or NULL with a message describing it */
static const char *real_at(lua_State *L, int idx, wb_real *out, char *buf, size_t n)
{
    if (lua_type(L, idx) != LUA_TNUMBER) {
        snprintf(buf, n, "number expected, got %s", luaL_typename(L, idx));
        return buf;
    }
    lua_Number x = lua_tonumber(L, idx);
    if (!isfinite(x)) {
        char s[32];
        snprintf(buf, n, "finite number expected, got %s", wbl_numstr(s, sizeof s, x));
        return buf;
    }
    *out = (wb_real)x;
    return NULL;
}

/* the value at idx as an integer in lo..hi, or NULL with a message */
static const char *int_at(lua_State *L, int idx, lua_Integer lo, lua_Integer hi, lua_Integer *out,
                          char *buf, size_t n)
{
    if (lua_type(L, idx) != LUA_TNUMBER) {
        snprintf(buf, n, "integer expected, got %s", luaL_typename(L, idx));
        return buf;
    }
    int isint;
    lua_Integer i = lua_tointegerx(L, idx, &isint);
    if (!isint) {
        char s[32];
        snprintf(buf, n, "integer expected, got %s", wbl_numstr(s, sizeof s, lua_tonumber(L, idx)));
        return buf;
    }
    if (i < lo || i > hi) {
        snprintf(buf, n, "%lld out of range (%lld..%lld)", (long long)i, (long long)lo, (long long)hi);
        return buf;
    }
    *out = i;
    return NULL;
}

wb_real wbl_checkreal(lua_State *L, int arg)
{
    char buf[96];
    wb_real x = 0;
    if (lua_type(L, arg) != LUA_TNUMBER) luaL_typeerror(L, arg, "number");
    if (real_at(L, arg, &x, buf, sizeof buf)) luaL_argerror(L, arg, buf);
    return x;
}

lua_Integer wbl_checkint(lua_State *L, int arg)
{
    char buf[96];
    lua_Integer i = 0;
    if (lua_type(L, arg) != LUA_TNUMBER) luaL_typeerror(L, arg, "integer");
    if (int_at(L, arg, LUA_MININTEGER, LUA_MAXINTEGER, &i, buf, sizeof buf)) luaL_argerror(L, arg, buf);
    return i;
}

int32_t wbl_particle_id(lua_State *L, const wb_world *w, int arg, lua_Integer id)
{
    int32_t n = wb_particle_count(w);
    if (id < 1 || id > n) {
        if (n == 0)
            return luaL_argerror(L, arg, lua_pushfstring(L, "particle id %I out of range (world has no particles)", id));
        return luaL_argerror(L, arg, lua_pushfstring(L, "particle id %I out of range (1..%d)", id, (int)n));
    }
    return (int32_t)(id - 1);
}

int32_t wbl_checkparticle(lua_State *L, const wb_world *w, int arg)
{
    if (lua_type(L, arg) != LUA_TNUMBER) luaL_typeerror(L, arg, "particle id");
    return wbl_particle_id(L, w, arg, wbl_checkint(L, arg));
}

/* ---- vectors ------------------------------------------------------------------------ */
/* check the table at idx holds exactly n numbers at 1..n; errors name `key` when given */
static void readvec(lua_State *L, int arg, const char *key, int idx, int n, bool integral,
                    lua_Integer lo, lua_Integer hi, wb_real *rout, int *iout)
{
    char msg[128];
    idx = lua_absindex(L, idx);
    if (!lua_istable(L, idx)) {
        snprintf(msg, sizeof msg, "table of %d %s expected, got %s", n, integral ? "integers" : "numbers",
                 luaL_typename(L, idx));
        goto fail;
    }
    int count = 0;
    lua_pushnil(L);
    while (lua_next(L, idx)) {
        count++;
        lua_pop(L, 1);
    }
    if (count != n || lua_rawlen(L, idx) != (size_t)n) {
        snprintf(msg, sizeof msg, "table of %d %s expected, got %d value%s", n,
                 integral ? "integers" : "numbers", count, count == 1 ? "" : "s");
        goto fail;
    }
    for (int i = 0; i < n; i++) {
        char why[96];
        const char *bad;
        lua_rawgeti(L, idx, i + 1);
        if (integral) {
            lua_Integer v = 0;
            bad = int_at(L, -1, lo, hi, &v, why, sizeof why);
            if (!bad) iout[i] = (int)v;
        } else {
            bad = real_at(L, -1, &rout[i], why, sizeof why);
        }
        lua_pop(L, 1);
        if (bad) {
            snprintf(msg, sizeof msg, "element %d: %s", i + 1, bad);
            goto fail;
        }
    }
    return;
fail:
    if (key) wbl_fielderror(L, arg, key, "%s", msg);
    luaL_argerror(L, arg, msg);
}

void wbl_checkvec(lua_State *L, int arg, int n, wb_real *out)
{
    readvec(L, arg, NULL, arg, n, false, 0, 0, out, NULL);
}

void wbl_checkreals(lua_State *L, int arg, int n, wb_real *out)
{
    for (int i = 0; i < n; i++) out[i] = wbl_checkreal(L, arg + i);
}

void wbl_pushreals(lua_State *L, const wb_real *v, int n)
{
    for (int i = 0; i < n; i++) lua_pushnumber(L, (lua_Number)v[i]);
}

/* ---- option tables ------------------------------------------------------------------- */
int wbl_fielderror(lua_State *L, int arg, const char *key, const char *fmt, ...)
{
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return luaL_argerror(L, arg, lua_pushfstring(L, "field '%s': %s", key, msg));
}

/* "a, b, c" of a NULL-terminated list, for error messages */
static void join(char *buf, size_t n, const char *const names[], const char *last_sep)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int i = 0; names[i] && len < n; i++) {
        const char *sep = i == 0 ? "" : names[i + 1] ? ", " : last_sep;
        len += (size_t)snprintf(buf + len, n - len, "%s%s", sep, names[i]);
    }
}

bool wbl_checkopts(lua_State *L, int arg, const char *const keys[], bool optional)
{
    if (optional && lua_isnoneornil(L, arg)) return false;
    if (!lua_istable(L, arg)) luaL_typeerror(L, arg, optional ? "table or nil" : "table");
    arg = lua_absindex(L, arg);
    lua_pushnil(L);
    while (lua_next(L, arg)) {
        lua_pop(L, 1);
        bool known = false;
        if (lua_type(L, -1) == LUA_TSTRING) {
            const char *k = lua_tostring(L, -1);
            for (int i = 0; keys[i] && !known; i++) known = strcmp(k, keys[i]) == 0;
        }
        if (!known) {
            char list[512];
            join(list, sizeof list, keys, ", ");
            if (lua_type(L, -1) == LUA_TSTRING)
                lua_pushfstring(L, "unknown key '%s'; expected one of: %s", lua_tostring(L, -1), list);
            else if (lua_type(L, -1) == LUA_TNUMBER)
                lua_pushfstring(L, "unknown key [%s]; expected one of: %s", luaL_tolstring(L, -1, NULL), list);
            else
                lua_pushfstring(L, "unknown key of type %s; expected one of: %s", luaL_typename(L, -1), list);
            luaL_argerror(L, arg, lua_tostring(L, -1));
        }
    }
    return true;
}

/* push t[key] (raw, like the key check) and report whether it is present */
static bool getopt(lua_State *L, int arg, const char *key)
{
    lua_pushstring(L, key);
    if (lua_rawget(L, arg) == LUA_TNIL) {
        lua_pop(L, 1);
        return false;
    }
    return true;
}

bool wbl_optreal(lua_State *L, int arg, const char *key, wb_real *out)
{
    char why[96];
    arg = lua_absindex(L, arg);
    if (!getopt(L, arg, key)) return false;
    if (real_at(L, -1, out, why, sizeof why)) wbl_fielderror(L, arg, key, "%s", why);
    lua_pop(L, 1);
    return true;
}

bool wbl_optinteger(lua_State *L, int arg, const char *key, lua_Integer lo, lua_Integer hi, lua_Integer *out)
{
    char why[96];
    arg = lua_absindex(L, arg);
    if (!getopt(L, arg, key)) return false;
    if (int_at(L, -1, lo, hi, out, why, sizeof why)) wbl_fielderror(L, arg, key, "%s", why);
    lua_pop(L, 1);
    return true;
}

bool wbl_optint(lua_State *L, int arg, const char *key, lua_Integer lo, lua_Integer hi, int *out)
{
    lua_Integer v = 0;
    if (!wbl_optinteger(L, arg, key, lo, hi, &v)) return false;
    *out = (int)v;
    return true;
}

bool wbl_optbool(lua_State *L, int arg, const char *key, bool *out)
{
    arg = lua_absindex(L, arg);
    if (!getopt(L, arg, key)) return false;
    if (!lua_isboolean(L, -1)) wbl_fielderror(L, arg, key, "boolean expected, got %s", luaL_typename(L, -1));
    *out = lua_toboolean(L, -1);
    lua_pop(L, 1);
    return true;
}

bool wbl_optvec(lua_State *L, int arg, const char *key, int n, wb_real *out)
{
    arg = lua_absindex(L, arg);
    if (!getopt(L, arg, key)) return false;
    readvec(L, arg, key, -1, n, false, 0, 0, out, NULL);
    lua_pop(L, 1);
    return true;
}

bool wbl_optivec(lua_State *L, int arg, const char *key, int n, lua_Integer lo, lua_Integer hi, int *out)
{
    arg = lua_absindex(L, arg);
    if (!getopt(L, arg, key)) return false;
    readvec(L, arg, key, -1, n, true, lo, hi, NULL, out);
    lua_pop(L, 1);
    return true;
}

int wbl_enum_index(lua_State *L, int arg, const char *s, const char *what, const char *const names[])
{
    for (int i = 0; names[i]; i++)
        if (strcmp(s, names[i]) == 0) return i;
    char list[256];
    join(list, sizeof list, names, " or ");
    return luaL_argerror(L, arg, lua_pushfstring(L, "unknown %s '%s' (expected %s)", what, s, list));
}

int wbl_optenum(lua_State *L, int arg, const char *key, const char *what, const char *const names[])
{
    arg = lua_absindex(L, arg);
    if (!getopt(L, arg, key)) return -1;
    if (lua_type(L, -1) != LUA_TSTRING)
        wbl_fielderror(L, arg, key, "string expected, got %s", luaL_typename(L, -1));
    int i = wbl_enum_index(L, arg, lua_tostring(L, -1), what, names);
    lua_pop(L, 1);
    return i;
}

/* ---- constraint options -------------------------------------------------------------- */
const char *const wbl_link_keys[] = { "compliance", "damping", "yield", "creep", "break_strain", "break_force", NULL };

void wbl_read_link(lua_State *L, int arg, wb_distance_def *d)
{
    wbl_optreal(L, arg, "compliance", &d->compliance);
    wbl_optreal(L, arg, "damping", &d->damping);
    wbl_optreal(L, arg, "yield", &d->yield);
    wbl_optreal(L, arg, "creep", &d->creep);
    wbl_optreal(L, arg, "break_strain", &d->break_strain);
    wbl_optreal(L, arg, "break_force", &d->break_force);
}

int wbl_fault_error(lua_State *L, const wb_fault *f, int first, int together, int opts)
{
    if (!f->msg) return 0;
    if (f->key) return wbl_fielderror(L, opts, f->key, "%s", f->why);
    return luaL_argerror(L, f->corner >= 0 ? first + f->corner : together, f->msg);
}

int wbl_status_error(lua_State *L, int arg, wb_status st, const char *what)
{
    switch (st) {
    case WB_ERR_NOMEM:
        if (wb_rt_get(L)->memory_budget == 0) return wb_rt_budget_error(L, "out of memory: %s", what);
        return wb_rt_budget_error(L, "out of memory: %s (the memory budget is %d MB; raise it with --memory-limit MB)",
                                  what, (int)(wb_rt_get(L)->memory_budget >> 20));
    case WB_ERR_LIMIT:
        return luaL_argerror(L, arg, lua_pushfstring(L,
            "%s: too large (limits: %d particles, %d constraints, %d colliders per world)",
            what, (int)WB_MAX_PARTICLES, (int)WB_MAX_CONSTRAINTS, (int)WB_MAX_COLLIDERS));
    case WB_ERR_ARG:
        return luaL_argerror(L, arg, lua_pushfstring(L, "%s", wb_last_error()));
    default:
        return luaL_error(L, "%s: unexpected core status %d", what, (int)st);
    }
}

/* ---- handles ----------------------------------------------------------------------------- */
void *wbl_handle(lua_State *L, int arg, const char *tname, wb_world **w)
{
    void *h = luaL_checkudata(L, arg, tname);
    lua_getiuservalue(L, arg, 1);
    wbl_world *ud = (wbl_world *)lua_touserdata(L, -1);
    lua_pop(L, 1); /* the handle itself still references the world */
    *w = ud ? ud->w : NULL;
    return h;
}

/* equal when they name the same object of the same world */
int wbl_handle_eq(lua_State *L, const char *tname, size_t size)
{
    void *a = luaL_testudata(L, 1, tname), *b = luaL_testudata(L, 2, tname);
    if (!a || !b || memcmp(a, b, size) != 0) {
        lua_pushboolean(L, 0);
        return 1;
    }
    lua_getiuservalue(L, 1, 1);
    lua_getiuservalue(L, 2, 1);
    lua_pushboolean(L, lua_rawequal(L, -1, -2));
    return 1;
}

/* ---- stepping ---------------------------------------------------------------------------- */
void wbl_step(lua_State *L, wb_world *w)
{
    int (*fn)(void *);
    void *ud;
    wb_rt_interrupt(L, &fn, &ud);
    wb_world_set_interrupt(w, fn, ud);
    wb_status st = wb_world_step(w);
    wb_world_set_interrupt(w, NULL, NULL); /* the runtime may be gone before the world is */
    if (st == WB_ERR_INTERRUPTED) {
        wb_rt_check_budgets(L);
        luaL_error(L, "step interrupted"); /* (a budget was spent: not reached) */
    }
    if (st == WB_ERR_NOMEM) wb_rt_budget_error(L, "out of memory stepping the world");
}

/* ---- after a frame -------------------------------------------------------------------- */
void wbl_after_frame(lua_State *L, int world_index)
{
    wbl_world *ud = wbl_checkworld_ud(L, world_index);
    /* numerical trouble is reported once per world: a per-frame message would flood
     * the terminal of a long run; w:warnings() gives the count */
    if (ud->w && !ud->warned && wb_world_warnings(ud->w) > 0) {
        ud->warned = 1;
        luaL_where(L, 1);
        fprintf(stderr, "wobble: warning: %s%s (reported once per world; see w:warnings())\n",
                lua_tostring(L, -1), wb_world_last_warning(ud->w));
        fflush(stderr);
        lua_pop(L, 1);
    }
    wbl_result_after_frame(L, world_index);
    wb_rt_after_frame(L, world_index);
}

/* young (Pa, > 0) and poisson ([0, 0.5)) of a tet solid's options at arg, when given (the
 * lattice in body.c, the tet bodies in volume.c: here so that neither calls the other); raises */
void wbl_read_neo(lua_State *L, int arg, wb_real *young, wb_real *poisson)
{
    if (lua_type(L, arg) != LUA_TTABLE) return;
    const bool has_young = wbl_optreal(L, arg, "young", young);
    if (has_young && !(*young > 0)) wbl_fielderror(L, arg, "young", "must be > 0 (Pa)");
    if (wbl_optreal(L, arg, "poisson", poisson)) {
        if (!(*poisson >= 0 && *poisson < 0.5)) wbl_fielderror(L, arg, "poisson", "must be in [0, 0.5)");
        if (!has_young && !(*young > 0)) wbl_fielderror(L, arg, "poisson", "needs young"); /* or a material */
    }
}

/* ---- files ---- */
bool wbl_write_png(const char *path, const uint8_t *rgb, int w, int h, char *err, size_t n)
{
    size_t bytes;
    char e[PATH_MAX + 160];
    void *png = wb_image_encode_png(rgb, w, h, &bytes);
    if (!png) {
        snprintf(err, n, "out of memory encoding %s", path);
        return false;
    }
    const bool ok = wbio_write_bytes(AT_FDCWD, path, path, png, bytes, e, sizeof e) == 0;
    free(png);
    if (!ok) snprintf(err, n, "cannot write %s", e);
    return ok;
}

const char *const *wbl_shape_names(const char *names[WB_SHAPE_COUNT + 1])
{
    for (int s = 0; s < WB_SHAPE_COUNT; s++) names[s] = wb_shape_info_of((wb_shape)s)->name;
    names[WB_SHAPE_COUNT] = NULL;
    return names;
}

void wbl_shape_keys(const char *const first[], const char *fields, const char *only, const char *const last[],
                    const char *keys[24], char buf[128])
{
    int n = 0;
    size_t used = 0;
    for (int i = 0; first[i] && n < 23; i++) keys[n++] = first[i];
    for (const char *p = fields; p && *p && n < 23;) {
        while (*p == ' ') p++;
        const char *e = p;
        while (*e && *e != ' ') e++;
        const size_t len = (size_t)(e - p);
        if (len == 0 || used + len + 1 > 128) break;
        memcpy(buf + used, p, len);
        buf[used + len] = 0;
        if (!only || wb_shape_takes(only, buf + used)) {
            keys[n++] = buf + used;
            used += len + 1;
        }
        p = e;
    }
    for (int i = 0; last[i] && n < 23; i++) keys[n++] = last[i];
    keys[n] = NULL;
}
