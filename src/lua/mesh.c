/* mesh.c: the mesh userdata: wobble.mesh{vertices, triangles}, wobble.load_mesh(path)
 * and their methods, and w:from_mesh(m, {...}), the particle graph of a mesh.
 *
 * Vertex and triangle ids are 1-based here as everywhere in Lua. A file that cannot be
 * read is an expected failure: load_mesh returns nil and "file: reason" (liolib's style);
 * misuse (a wrong argument type) raises. */
#include <limits.h>
#include <math.h>
#include <string.h>

#include "io/io.h"
#include "mesh.h"
#include "sandbox.h"

typedef struct wbl_mesh {
    wb_mesh *m;
    size_t charged;   /* bytes charged to the memory budget for m (0: none) */
} wbl_mesh;

/* ---- the memory budget: meshes, skins and renderers live outside the Lua heap ----------------- */
static bool fits(const wb_memory *m, size_t bytes)
{
    return !m->limit || (bytes <= m->limit && m->used <= m->limit - bytes);
}

void wbl_charge(lua_State *L, size_t bytes, const char *what)
{
    wb_memory *m = &wb_rt_get(L)->memory;
    /* Lua's collector only sees the small userdata: what it would free out there is
     * invisible to it, so collect before refusing (as Lua does for its own heap) */
    if (!fits(m, bytes)) lua_gc(L, LUA_GCCOLLECT);
    if (!fits(m, bytes))
        wb_rt_budget_error(L, "%s needs about %.0f MB, over the memory budget of %.0f MB (%.0f MB of it left; "
                              "--memory-limit MB)", what, bytes / 1048576.0, m->limit / 1048576.0,
                           (m->used < m->limit ? m->limit - m->used : 0) / 1048576.0);
    m->used += bytes;
}

void wbl_release(lua_State *L, size_t bytes)
{
    wb_memory *m = &wb_rt_get(L)->memory;
    m->used -= bytes < m->used ? bytes : m->used;
}

size_t wbl_mesh_bytes(int64_t nv, int64_t nt)
{
    /* positions and normals (nv x 3 each), triangles (nt x 3), as wb_mesh_create allocates */
    return sizeof(wb_mesh) + (size_t)(nv > 0 ? nv : 1) * 6 * sizeof(wb_real) + (size_t)(nt > 0 ? nt : 1) * 3 * sizeof(int32_t);
}

/* ---- handles ---------------------------------------------------------------------------------- */
wb_mesh **wbl_push_mesh_slot(lua_State *L)
{
    wbl_mesh *u = (wbl_mesh *)lua_newuserdatauv(L, sizeof *u, 0);
    u->m = NULL;
    u->charged = 0;
    luaL_setmetatable(L, WBL_MESH);
    return &u->m;
}

/* charge the mesh userdata on top for a mesh of that size (before or after it is made) */
static void charge_top(lua_State *L, int64_t nv, int64_t nt, const char *what)
{
    wbl_mesh *u = (wbl_mesh *)lua_touserdata(L, -1);
    const size_t bytes = wbl_mesh_bytes(nv, nt);
    wbl_charge(L, bytes, what);
    u->charged += bytes;
}

wb_mesh **wbl_push_mesh_charged(lua_State *L, int64_t nv, int64_t nt, const char *what)
{
    wb_mesh **slot = wbl_push_mesh_slot(L);
    charge_top(L, nv, nt, what);
    return slot;
}

wb_mesh *wbl_checkmesh(lua_State *L, int arg)
{
    wbl_mesh *u = (wbl_mesh *)luaL_checkudata(L, arg, WBL_MESH);
    if (!u->m) luaL_argerror(L, arg, "mesh is closed");
    return u->m;
}

static int vertex_id(lua_State *L, const wb_mesh *m, int arg)
{
    lua_Integer i = wbl_checkint(L, arg);
    if (i < 1 || i > m->nv) luaL_argerror(L, arg, lua_pushfstring(L, "vertex %I out of range (1..%d)", i, (int)m->nv));
    return (int)(i - 1);
}

/* ---- wobble.mesh{vertices = ..., triangles = ...} -------------------------------------------- */
/* a list of n-tuples, nested ({{x,y,z}, ...}) or flat ({x,y,z, x,y,z, ...}), as numbers */
static lua_Integer read_tuples(lua_State *L, int arg, const char *key, int n, int integral, void **out)
{
    lua_getfield(L, arg, key);
    if (!lua_istable(L, -1)) wbl_fielderror(L, arg, key, "table expected, got %s", luaL_typename(L, -1));
    const int t = lua_gettop(L);
    const lua_Integer len = (lua_Integer)lua_rawlen(L, t);
    const int nested = len > 0 && (lua_rawgeti(L, t, 1), lua_istable(L, -1));
    if (len > 0) lua_pop(L, 1);
    const lua_Integer count = nested ? len : len / n;
    if (!nested && len % n) wbl_fielderror(L, arg, key, "a flat list needs a multiple of %d numbers, got %lld", n, (long long)len);
    if (count > (integral ? WB_MAX_CONSTRAINTS : WB_MAX_PARTICLES)) wbl_fielderror(L, arg, key, "too many entries");
    void *buf = lua_newuserdatauv(L, (size_t)(count > 0 ? count : 1) * (size_t)n * (integral ? sizeof(int32_t) : sizeof(wb_real)), 0);
    for (lua_Integer i = 0; i < count; i++) {
        if (nested) {
            lua_rawgeti(L, t, i + 1);
            if (!lua_istable(L, -1) || lua_rawlen(L, -1) != (size_t)n)
                wbl_fielderror(L, arg, key, "entry %lld: table of %d %s expected", (long long)i + 1, n, integral ? "integers" : "numbers");
        }
        for (int c = 0; c < n; c++) {
            if (nested) lua_rawgeti(L, -1, c + 1);
            else lua_rawgeti(L, t, i * n + c + 1);
            int isnum = lua_type(L, -1) == LUA_TNUMBER, isint = 0;
            lua_Integer iv = isnum ? lua_tointegerx(L, -1, &isint) : 0;
            lua_Number x = isnum ? lua_tonumber(L, -1) : 0;
            if (integral && !isint)
                wbl_fielderror(L, arg, key, "entry %lld: integer expected, got %s", (long long)i + 1, luaL_typename(L, -1));
            if (!integral && (!isnum || x != x || x - x != 0))
                wbl_fielderror(L, arg, key, "entry %lld: finite number expected, got %s", (long long)i + 1, isnum ? "a non-finite one" : luaL_typename(L, -1));
            if (integral) {
                if (iv < 1 || iv > INT32_MAX) wbl_fielderror(L, arg, key, "entry %lld: vertex %lld out of range", (long long)i + 1, (long long)iv);
                ((int32_t *)buf)[i * n + c] = (int32_t)(iv - 1);
            } else {
                ((wb_real *)buf)[i * n + c] = (wb_real)x;
            }
            lua_pop(L, 1);
        }
        if (nested) lua_pop(L, 1);
    }
    lua_replace(L, t); /* keep the buffer where the list was: collected with the stack */
    *out = buf;
    return count;
}

static const char *const mesh_keys[] = { "vertices", "triangles", "weld", NULL };

static int l_mesh(lua_State *L)
{
    wbl_checkopts(L, 1, mesh_keys, false);
    void *v, *t;
    lua_Integer nv = read_tuples(L, 1, "vertices", 3, 0, &v);
    lua_Integer nt = read_tuples(L, 1, "triangles", 3, 1, &t);
    const int32_t *tri = t;
    for (lua_Integer i = 0; i < 3 * nt; i++)
        if (tri[i] >= nv)
            wbl_fielderror(L, 1, "triangles", "entry %lld: vertex %d out of range (1..%lld)", (long long)(i / 3 + 1), (int)tri[i] + 1, (long long)nv);
    wb_real weld = -1;
    lua_getfield(L, 1, "weld");
    /* true: the same default as load_mesh, near-coincident vertices merged too */
    if (lua_isboolean(L, -1)) weld = lua_toboolean(L, -1) ? -2 : -1;
    else if (!lua_isnil(L, -1) && wbl_optreal(L, 1, "weld", &weld) && weld < 0)
        return wbl_fielderror(L, 1, "weld", "tolerance must be >= 0");
    lua_pop(L, 1);
    wb_mesh **slot = wbl_push_mesh_charged(L, nv, nt, "wobble.mesh");
    wb_status st;
    *slot = wb_mesh_create(v, (int32_t)nv, tri, (int32_t)nt, &st);
    if (!*slot) return wbl_status_error(L, 1, st, "mesh");
    if (weld == -2) weld = wb_mesh_weld_tolerance(*slot);
    if (weld >= 0 && (st = wb_mesh_weld(*slot, weld, NULL)) != WB_OK) return wbl_status_error(L, 1, st, "mesh");
    return 1;
}

/* ---- wobble.load_mesh(path, {scale, weld, timeout}) ------------------------------------------- */
static const char *const load_keys[] = { "scale", "weld", "timeout", NULL };

static int l_load_mesh(lua_State *L)
{
    const char *name = wbl_checkfilename(L, 1);
    wbio_mesh_opts o = { 1, true, -1, 0 };
    if (wbl_checkopts(L, 2, load_keys, true)) {
        if (wbl_optreal(L, 2, "scale", &o.scale) && !(o.scale > 0)) return wbl_fielderror(L, 2, "scale", "must be > 0");
        lua_getfield(L, 2, "weld");
        if (lua_isboolean(L, -1)) o.weld = lua_toboolean(L, -1);
        else if (!lua_isnil(L, -1) && wbl_optreal(L, 2, "weld", &o.tol) && o.tol < 0)
            return wbl_fielderror(L, 2, "weld", "tolerance must be >= 0");
        lua_pop(L, 1);
        wb_real t = 0;
        if (wbl_optreal(L, 2, "timeout", &t) && !(t > 0)) return wbl_fielderror(L, 2, "timeout", "must be > 0");
        o.timeout = t;
    }
    char path[4096], err[1024];
    wbl_path(L, name, 0, path, sizeof path);
    if (!wbl_import_mesh(L, path, name, &o, "load_mesh", err, sizeof err)) {
        luaL_pushfail(L);
        lua_pushstring(L, err);
        return 2;
    }
    return 1;
}

wb_mesh *wbl_import_mesh(lua_State *L, const char *path, const char *name, const wbio_mesh_opts *o, const char *who,
                         char *err, size_t n)
{
    /* the import may take what is left of the memory budget, and stops with the run's
     * other budgets (the time limit): either is a budget error, not a file's failure */
    const wb_memory *mem = &wb_rt_get(L)->memory;
    wbio_budget b = { 0, NULL, NULL, false };
    if (mem->limit) {
        lua_gc(L, LUA_GCCOLLECT);   /* what unreachable meshes hold is left to the import */
        b.max_bytes = mem->used < mem->limit ? mem->limit - mem->used : 1;
    }
    wb_rt_interrupt(L, &b.interrupt, &b.interrupt_ud);
    wb_mesh **slot = wbl_push_mesh_slot(L);
    *slot = wbio_load_mesh_within(path, name, o, &b, wbl_allow, L, err, n);
    if (b.stopped) {
        wb_rt_check_budgets(L);   /* the time limit: its own message */
        wb_rt_budget_error(L, "%s: %s: memory limit of %.0f MB exceeded (--memory-limit MB)", who, err,
                           mem->limit / 1048576.0);
    }
    if (*slot) charge_top(L, (*slot)->nv, (*slot)->nt, name);
    return *slot;
}

/* ---- methods ---------------------------------------------------------------------------------- */
static int m_vertex_count(lua_State *L)
{
    lua_pushinteger(L, wbl_checkmesh(L, 1)->nv);
    return 1;
}

static int m_triangle_count(lua_State *L)
{
    lua_pushinteger(L, wbl_checkmesh(L, 1)->nt);
    return 1;
}

static int m_vertex(lua_State *L)
{
    const wb_mesh *m = wbl_checkmesh(L, 1);
    wbl_pushreals(L, &m->v[3 * vertex_id(L, m, 2)], 3);
    return 3;
}

static int m_normal(lua_State *L)
{
    const wb_mesh *m = wbl_checkmesh(L, 1);
    wbl_pushreals(L, &m->n[3 * vertex_id(L, m, 2)], 3);
    return 3;
}

static int m_triangle(lua_State *L)
{
    const wb_mesh *m = wbl_checkmesh(L, 1);
    lua_Integer i = wbl_checkint(L, 2);
    if (i < 1 || i > m->nt) return luaL_argerror(L, 2, lua_pushfstring(L, "triangle %I out of range (1..%d)", i, (int)m->nt));
    for (int c = 0; c < 3; c++) lua_pushinteger(L, (lua_Integer)m->tri[3 * (i - 1) + c] + 1);
    return 3;
}

static int m_bounds(lua_State *L)
{
    wb_real lo[3], hi[3];
    if (!wb_mesh_bounds(wbl_checkmesh(L, 1), lo, hi)) {
        lua_pushnil(L);
        return 1;
    }
    wbl_pushreals(L, lo, 3);
    wbl_pushreals(L, hi, 3);
    return 6;
}

static const char *const transform_keys[] = { "scale", "translate", NULL };

/* m:transform{scale = s, translate = {x,y,z}}: in place, returns m */
static int m_transform(lua_State *L)
{
    wb_mesh *m = wbl_checkmesh(L, 1);
    wb_real s = 1, t[3] = { 0, 0, 0 };
    wbl_checkopts(L, 2, transform_keys, false);
    if (wbl_optreal(L, 2, "scale", &s) && s == 0) return wbl_fielderror(L, 2, "scale", "must not be 0");
    wbl_optvec(L, 2, "translate", 3, t);
    /* checked before anything moves: a mesh with an infinite vertex would reach the core
     * (w:from_mesh, w:skin) as inf and NaN */
    for (int32_t i = 0; i < m->nv; i++)
        for (int c = 0; c < 3; c++)
            if (!isfinite(m->v[3 * i + c] * s + t[c]))
                return luaL_error(L, "transform: vertex %d would not be finite", (int)i + 1);
    wb_mesh_transform(m, s, t);
    lua_settop(L, 1);
    return 1;
}

static int m_copy(lua_State *L)
{
    const wb_mesh *m = wbl_checkmesh(L, 1);
    wb_mesh **slot = wbl_push_mesh_charged(L, m->nv, m->nt, "m:copy()");
    *slot = wb_mesh_copy(m);
    if (!*slot) return wb_rt_budget_error(L, "out of memory copying a mesh");
    return 1;
}

/* m:save(path) by extension, m:save_obj(path): true, or nil and "file: reason" */
static int save_as(lua_State *L, const char *ext)
{
    const wb_mesh *m = wbl_checkmesh(L, 1);
    const char *name = wbl_checkfilename(L, 2);
    char path[4096], err[1024];
    if (ext) {
        const char *dot = strrchr(name, '.');
        if (!dot || strcmp(dot, ext)) return luaL_argerror(L, 2, lua_pushfstring(L, "a %s file name expected", ext));
    }
    wbl_path(L, name, 1, path, sizeof path);
    if (wbio_save_mesh(m, NULL, path, name, wbl_allow, L, err, sizeof err)) {
        luaL_pushfail(L);
        lua_pushstring(L, err);
        return 2;
    }
    lua_pushboolean(L, 1);
    return 1;
}

static int m_save(lua_State *L) { return save_as(L, NULL); }
static int m_save_obj(lua_State *L) { return save_as(L, ".obj"); }

static int m_close(lua_State *L)
{
    wbl_mesh *u = (wbl_mesh *)luaL_checkudata(L, 1, WBL_MESH);
    wb_mesh_destroy(u->m);
    u->m = NULL;
    wbl_release(L, u->charged);
    u->charged = 0;
    return 0;
}

static int m_tostring(lua_State *L)
{
    wbl_mesh *u = (wbl_mesh *)luaL_checkudata(L, 1, WBL_MESH);
    if (!u->m) lua_pushfstring(L, "wobble.mesh: %p (closed)", (void *)u);
    else lua_pushfstring(L, "wobble.mesh: %p (%d vertices, %d triangles)", (void *)u, (int)u->m->nv, (int)u->m->nt);
    return 1;
}

/* ---- w:from_mesh(m, {tets = true, ...}): filled with tets by tetgen (io/tets.c), lua/volume.c builds */
static const char *const from_mesh_tets_keys[] = {
    "tets", "max_volume", "quality", "keep_surface", "timeout", "mass", "radius", "volume_compliance", "young", "poisson",
    "compliance", "damping", "yield", "creep", "break_strain", "break_force", "collide", "self_collide", "friction",
    "material", NULL
};

/* the volume a closed mesh encloses (divergence theorem over its triangles), m^3 */
static double enclosed_volume(const wb_mesh *m)
{
    if (m->nv == 0) return 0;
    double v = 0, o[3] = { m->v[0], m->v[1], m->v[2] }; /* about a vertex: far from 0 it loses no digits */
    for (int32_t t = 0; t < m->nt; t++) {
        double p[3], q[3], r[3];
        for (int c = 0; c < 3; c++) {
            p[c] = m->v[3 * m->tri[3 * t] + c] - o[c];
            q[c] = m->v[3 * m->tri[3 * t + 1] + c] - o[c];
            r[c] = m->v[3 * m->tri[3 * t + 2] + c] - o[c];
        }
        v += (p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0]) + p[2] * (q[0] * r[1] - q[1] * r[0])) / 6;
    }
    return isfinite(v) ? fabs(v) : 0;
}

static int from_mesh_tets(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    const wb_mesh *m = wbl_checkmesh(L, 2);
    wbl_checkopts(L, 3, from_mesh_tets_keys, false);
    wb_tet_body_def d = wb_tet_body_default_def();
    const wb_material *mat = wbl_opt_material(L, 3);
    if (mat) {
        d.young = mat->young;
        d.poisson = mat->poisson;
    }
    const bool auto_radius = wbl_read_tet_body(L, 3, &d);
    wbl_contact_opts co;
    wbl_read_contact_opts(L, 3, &co);
    wbl_material_friction(L, 3, mat, &co);
    wbio_tetgen_opts o = { 0, 2, -1, false, 0, false };
    wb_real x;
    if (wbl_optreal(L, 3, "max_volume", &x)) {
        if (!(x > 0)) return wbl_fielderror(L, 3, "max_volume", "must be > 0 (m^3)");
        o.max_volume = x;
        o.bound_given = true;
    } else {
        /* a solid resolved whatever the mesh: tets of at most a thousandth of the enclosed
         * volume (a cube: ~700 particles, ~2,400 tets; the count does not change with the
         * mesh's scale, and a fine mesh's own vertices add to it) */
        o.max_volume = enclosed_volume(m) / 1000;
    }
    /* quality: tetgen's radius-edge ratio bound (-q), default 2; false: none */
    lua_getfield(L, 3, "quality");
    if (lua_isboolean(L, -1)) {
        if (lua_toboolean(L, -1)) return wbl_fielderror(L, 3, "quality", "a ratio (>= 1.1) or false expected");
        o.quality = 0;
    } else if (wbl_optreal(L, 3, "quality", &x)) {
        if (!(x >= 1.1 && x <= 100)) return wbl_fielderror(L, 3, "quality", "radius-edge ratio must be in 1.1..100");
        o.quality = x;
    }
    lua_pop(L, 1);
    bool keep;
    if (wbl_optbool(L, 3, "keep_surface", &keep)) o.keep_surface = keep;
    if (wbl_optreal(L, 3, "timeout", &x)) {
        if (!(x > 0)) return wbl_fielderror(L, 3, "timeout", "must be > 0");
        o.timeout = x;
    }
    lua_settop(L, 3);
    /* tetgen may take what is left of the memory budget, and stops with the run's time limit */
    const wb_memory *mem = &wb_rt_get(L)->memory;
    wbio_budget b = { 0, NULL, NULL, false };
    if (mem->limit) {
        lua_gc(L, LUA_GCCOLLECT);
        b.max_bytes = mem->used < mem->limit ? mem->limit - mem->used : 1;
    }
    wb_rt_interrupt(L, &b.interrupt, &b.interrupt_ud);
    wbio_tets *t = wbl_push_tets(L); /* 4 */
    char err[1024];
    if (wbio_tetgen(m, &o, &b, t, err, sizeof err)) {
        if (b.stopped) {
            wb_rt_check_budgets(L);
            return wb_rt_budget_error(L, "from_mesh: %s: memory limit of %.0f MB exceeded (--memory-limit MB)", err,
                                      mem->limit / 1048576.0);
        }
        return luaL_argerror(L, 2, err);
    }
    wbl_tet_preset(L, 3, mat, t, &d);
    /* with the surface kept, the mesh's vertices are tetgen's first nodes: its triangles are
     * the body's surface, as they were; else the tets' boundary (tetgen split it) */
    keep = o.kept && t->nv >= m->nv;
    for (int64_t i = 0; keep && i < 3 * (int64_t)m->nv; i++) {
        const wb_real a = t->v[i], c = m->v[i];
        keep = fabs(a - c) <= 1e-9 * (1 + fabs(c));
    }
    return wbl_push_tet_body(L, w, t, keep ? m->tri : NULL, keep ? m->nt : 0, &d, auto_radius, &co, "from_mesh");
}

/* ---- w:from_mesh(m, {...}) --------------------------------------------------------------------- */
static const char *const from_mesh_keys[] = {
    "mass", "radius", "target", "neighbours", "surface", "tets",
    "compliance", "damping", "yield", "creep", "break_strain", "break_force", "collide", "self_collide", "friction",
    "material", NULL
};

static int w_from_mesh(lua_State *L)
{
    /* tets = true: filled with tetrahedra by tetgen, options of their own (lua/volume.c) */
    if (lua_type(L, 3) == LUA_TTABLE && lua_getfield(L, 3, "tets") != LUA_TNIL) {
        /* a boolean only: tets = 0 is true in Lua and would silently fill the mesh */
        if (!lua_isboolean(L, -1)) return wbl_fielderror(L, 3, "tets", "boolean expected, got %s", luaL_typename(L, -1));
        const bool tets = lua_toboolean(L, -1);
        lua_pop(L, 1);
        if (tets) return from_mesh_tets(L);
    }
    wb_world *w = wbl_checkworld(L, 1);
    const wb_mesh *m = wbl_checkmesh(L, 2);
    /* the tet options mean nothing for a body of links: say what they need, not just "unknown" */
    static const char *const tet_only[] = { "volume_compliance", "max_volume", "quality", "keep_surface", "timeout",
                                            "young", "poisson", NULL };
    /* a preset on a body of links: its friction, and its mass from the enclosed volume of a
     * closed mesh; the links stay as given (a surface of links has no Young's modulus) */
    const wb_material *mat = wbl_opt_material(L, 3);
    for (int i = 0; tet_only[i] && lua_type(L, 3) == LUA_TTABLE; i++) {
        const int given = lua_getfield(L, 3, tet_only[i]) != LUA_TNIL;
        lua_pop(L, 1);
        if (given) return wbl_fielderror(L, 3, tet_only[i], "needs tets = true");
    }
    wb_from_mesh_def d = wb_from_mesh_default_def();
    int32_t ea, eb;
    if (mat && wb_mesh_open_edges(m, &ea, &eb) == 0) {
        const double vol = enclosed_volume(m);
        if (vol > 0) d.mass = mat->density * vol;
    }
    bool auto_radius = true; /* half the spacing, set after building */
    wbl_contact_opts co;
    wbl_read_contact_opts(L, 3, &co);
    wbl_material_friction(L, 3, mat, &co);
    if (wbl_checkopts(L, 3, from_mesh_keys, true)) {
        if (wbl_optreal(L, 3, "mass", &d.mass) && !(d.mass > 0)) return wbl_fielderror(L, 3, "mass", "must be > 0");
        if (wbl_optreal(L, 3, "radius", &d.radius)) {
            if (d.radius < 0) return wbl_fielderror(L, 3, "radius", "must be >= 0");
            auto_radius = false;
        }
        wbl_optint(L, 3, "target", 1, WB_MAX_PARTICLES, &d.target);
        wbl_optint(L, 3, "neighbours", 0, 32, &d.neighbours);
        wbl_optbool(L, 3, "surface", &d.surface);
        wbl_read_link(L, 3, &d.link);
        const char *e = wb_distance_def_check(&d.link);
        if (e) return luaL_argerror(L, 3, e);
    }
    lua_settop(L, 3);
    const int32_t nd0 = wb_distance_count(w);
    wbl_body_begin(L, d.target > 0 && d.target < m->nv ? d.target : m->nv);
    wb_body b;
    wb_status st = wb_from_mesh(w, m, &d, &b);
    if (st != WB_OK) return wbl_status_error(L, st == WB_ERR_ARG ? 2 : 3, st, "from_mesh");
    if (auto_radius) wbl_default_radius(w, b);
    wbl_apply_contact_opts(w, b, &co);
    wbl_body_end(L, 1, b, wb_distance_count(w) - nd0);
    return 1;
}

static const luaL_Reg mesh_methods[] = {
    { "vertex_count", m_vertex_count },
    { "triangle_count", m_triangle_count },
    { "vertex", m_vertex },
    { "normal", m_normal },
    { "triangle", m_triangle },
    { "bounds", m_bounds },
    { "transform", m_transform },
    { "copy", m_copy },
    { "save", m_save },
    { "save_obj", m_save_obj },
    { "close", m_close },
    { NULL, NULL }
};

static const luaL_Reg mesh_meta[] = {
    { "__index", NULL },
    { "__gc", m_close },
    { "__close", m_close },
    { "__tostring", m_tostring },
    { NULL, NULL }
};

static const luaL_Reg module_funcs[] = {
    { "mesh", l_mesh },
    { "load_mesh", l_load_mesh },
    { NULL, NULL }
};

static const luaL_Reg world_methods[] = {
    { "from_mesh", w_from_mesh },
    { NULL, NULL }
};

void wbl_open_mesh(lua_State *L)
{
    luaL_newmetatable(L, WBL_MESH);
    luaL_setfuncs(L, mesh_meta, 0);
    luaL_newlibtable(L, mesh_methods);
    luaL_setfuncs(L, mesh_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    luaL_setfuncs(L, module_funcs, 0); /* into the module table at the top */
    wbl_add_world_methods(L, world_methods);
}
