/* body.c: the builders w:cloth{...}, w:rope{...}, w:lattice{...} and the body
 * table they return: { particles = {ids...}, first = id, count = n, world = w,
 * constraint_count = m } with methods pin_where, pin_all and unpin_all.
 * Bodies are plain tables (scripts may add fields); the methods come from a
 * shared metatable. */
#include <math.h>

#include "util.h"

/* ---- the body table -------------------------------------------------------------- */
/* the body table and its particles array are allocated before the core builds, so
 * a Lua memory error cannot leave particles the script has no body for */
void wbl_body_begin(lua_State *L, int64_t count)
{
    lua_createtable(L, 0, 5);
    lua_createtable(L, count > 0 && count <= WB_MAX_PARTICLES ? (int)count : 0, 0);
}

void wbl_body_end(lua_State *L, int world_index, wb_body b, int32_t constraints)
{
    world_index = lua_absindex(L, world_index);
    for (int32_t i = 0; i < b.count; i++) {
        lua_pushinteger(L, (lua_Integer)b.first + i + 1);
        lua_rawseti(L, -2, (lua_Integer)i + 1);
    }
    lua_setfield(L, -2, "particles");
    lua_pushinteger(L, (lua_Integer)b.first + 1);
    lua_setfield(L, -2, "first");
    lua_pushinteger(L, b.count);
    lua_setfield(L, -2, "count");
    lua_pushinteger(L, constraints);
    lua_setfield(L, -2, "constraint_count");
    lua_pushvalue(L, world_index);
    lua_setfield(L, -2, "world");
    if (b.group > 0) {
        lua_pushinteger(L, b.group);
        lua_setfield(L, -2, "group");
    }
    luaL_setmetatable(L, WBL_BODY);
}

void wbl_read_contact_opts(lua_State *L, int arg, wbl_contact_opts *o)
{
    o->collide = true;
    o->self_collide = false;
    o->friction = 0;
    if (lua_type(L, arg) != LUA_TTABLE) return;
    wbl_optbool(L, arg, "collide", &o->collide);
    wbl_optbool(L, arg, "self_collide", &o->self_collide);
    if (wbl_optreal(L, arg, "friction", &o->friction) && !(o->friction >= 0 && isfinite(o->friction)))
        wbl_fielderror(L, arg, "friction", "must be a finite number >= 0");
}

void wbl_apply_contact_opts(wb_world *w, wb_body b, const wbl_contact_opts *o)
{
    wb_body_set_contacts(w, b, o->collide, o->self_collide, o->friction);
}

void wbl_default_radius(wb_world *w, wb_body b)
{
    const wb_real r = wb_body_spacing(w, b) / 2;
    for (int32_t i = 0; i < b.count; i++) wb_particle_set_radius(w, b.first + i, r);
}

void wbl_push_body(lua_State *L, int world_index, wb_body b, int32_t constraints)
{
    world_index = lua_absindex(L, world_index);
    wbl_body_begin(L, b.count);
    wbl_body_end(L, world_index, b, constraints);
}

/* push body.world and body.particles (at top-1, top); returns the world */
static wb_world *body_parts(lua_State *L)
{
    luaL_checktype(L, 1, LUA_TTABLE);
    lua_getfield(L, 1, "world");
    if (!luaL_testudata(L, -1, WBL_WORLD)) luaL_argerror(L, 1, "body expected (no 'world' field)");
    wb_world *w = wbl_checkworld(L, lua_gettop(L));
    if (lua_getfield(L, 1, "particles") != LUA_TTABLE) luaL_argerror(L, 1, "body expected (no 'particles' table)");
    return w;
}

/* the i-th id of the particles table at top, checked (scripts may edit the table) */
static int32_t body_id(lua_State *L, const wb_world *w, lua_Integer i)
{
    lua_rawgeti(L, -1, i);
    if (lua_type(L, -1) != LUA_TNUMBER || !lua_isinteger(L, -1))
        luaL_argerror(L, 1, lua_pushfstring(L, "particles[%I]: particle id expected, got %s", i, luaL_typename(L, -1)));
    int32_t p = wbl_particle_id(L, w, 1, lua_tointeger(L, -1));
    lua_pop(L, 1);
    return p;
}

/* body:pin_where(function(x, y, z, id) return bool end) -> number pinned */
static int body_pin_where(lua_State *L)
{
    luaL_checktype(L, 2, LUA_TFUNCTION);
    lua_settop(L, 2);
    wb_world *w = body_parts(L); /* 3: world, 4: particles */
    lua_Integer n = (lua_Integer)lua_rawlen(L, 4), pinned = 0;
    for (lua_Integer i = 1; i <= n; i++) {
        int32_t p = body_id(L, w, i);
        wb_real x[3];
        wb_particle_position(w, p, x);
        lua_pushvalue(L, 2);
        wbl_pushreals(L, x, 3);
        lua_pushinteger(L, (lua_Integer)p + 1);
        lua_call(L, 4, 1);
        int yes = lua_toboolean(L, -1);
        lua_pop(L, 1);
        w = wbl_checkworld(L, 3); /* the predicate may have closed it */
        if (yes) {
            wb_particle_pin(w, p, NULL);
            pinned++;
        }
    }
    lua_pushinteger(L, pinned);
    return 1;
}

static int body_pin_all(lua_State *L)
{
    lua_settop(L, 1);
    wb_world *w = body_parts(L);
    lua_Integer n = (lua_Integer)lua_rawlen(L, 3);
    for (lua_Integer i = 1; i <= n; i++) wb_particle_pin(w, body_id(L, w, i), NULL);
    lua_pushinteger(L, n);
    return 1;
}

static int body_unpin_all(lua_State *L)
{
    lua_settop(L, 1);
    wb_world *w = body_parts(L);
    lua_Integer n = (lua_Integer)lua_rawlen(L, 3);
    for (lua_Integer i = 1; i <= n; i++) wb_particle_unpin(w, body_id(L, w, i));
    lua_pushinteger(L, n);
    return 1;
}

static int body_tostring(lua_State *L)
{
    luaL_checktype(L, 1, LUA_TTABLE);
    lua_getfield(L, 1, "count");
    lua_pushfstring(L, "wobble.body: %p (%d particles)", lua_topointer(L, 1), (int)lua_tointeger(L, -1));
    return 1;
}

/* ---- builders ------------------------------------------------------------------------- */
/* run a builder, then push the body; the constraint count is the core's difference */
#define BUILD(L, w, call, what, np)                                                 \
    do {                                                                            \
        wb_body b_;                                                                 \
        wbl_body_begin(L, np);                                                      \
        int32_t nd0_ = wb_distance_count(w);                                        \
        wb_status st_ = call(w, &d, &b_);                                           \
        if (st_ != WB_OK) return wbl_status_error(L, 2, st_, what);                 \
        if (auto_radius) wbl_default_radius(w, b_);                                 \
        wbl_apply_contact_opts(w, b_, &co);                                         \
        wbl_body_end(L, 1, b_, wb_distance_count(w) - nd0_);                        \
        return 1;                                                                   \
    } while (0)

/* returns whether the radius is the default (half the spacing, set after building) */
static bool read_mass_radius(lua_State *L, wb_real *mass, wb_real *radius)
{
    if (wbl_optreal(L, 2, "mass", mass) && *mass <= 0) wbl_fielderror(L, 2, "mass", "must be > 0");
    if (wbl_optreal(L, 2, "radius", radius)) {
        if (*radius < 0) wbl_fielderror(L, 2, "radius", "must be >= 0");
        return false;
    }
    return true;
}

static void check_link(lua_State *L, const wb_distance_def *d)
{
    const char *err = wb_distance_def_check(d);
    if (err) luaL_argerror(L, 2, err);
}

static const char *const cloth_keys[] = {
    "origin", "size", "res", "mass", "radius", "shear", "bend", "bend_links",
    "compliance", "damping", "yield", "creep", "break_strain", "break_force", "collide", "self_collide", "friction",
    "material", NULL
};

static int w_cloth(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    wb_cloth_def d = wb_cloth_default_def();
    wbl_checkopts(L, 2, cloth_keys, false);
    wbl_optvec(L, 2, "origin", 3, d.origin);
    if (wbl_optvec(L, 2, "size", 2, d.size) && !(d.size[0] > 0 && d.size[1] > 0))
        return wbl_fielderror(L, 2, "size", "both sizes must be > 0");
    wbl_optivec(L, 2, "res", 2, 2, WB_MAX_PARTICLES, d.res);
    /* a preset: a sheet of its thickness t: mass rho t A, links of stiffness E t and
     * dashpots eta t (a square grid's links along one axis carry E t per unit width) */
    const wb_material *mat = wbl_opt_material(L, 2);
    if (mat) {
        const wb_real t = mat->thickness;
        d.mass = mat->density * t * d.size[0] * d.size[1];
        d.link.compliance = 1 / (mat->young * t);
        d.link.damping = mat->viscosity * t;
        /* the plate's bending stiffness D = E t^3 / 12 (N m) as each hinge's: a hinge of a
         * square grid spans about as much sheet as it is long */
        d.bend = 12 / (mat->young * t * t * t);
    }
    const bool auto_radius = read_mass_radius(L, &d.mass, &d.radius);
    wbl_contact_opts co;
    wbl_read_contact_opts(L, 2, &co);
    wbl_material_friction(L, 2, mat, &co);
    wbl_optbool(L, 2, "shear", &d.shear);
    wbl_read_link(L, 2, &d.link);
    /* bend (dihedral, per interior edge): nil/false = none, true = rigid (0), a number =
     * its compliance in rad/(N m) */
    lua_getfield(L, 2, "bend");
    if (lua_isboolean(L, -1)) d.bend = lua_toboolean(L, -1) ? 0 : -1;
    else if (!lua_isnil(L, -1) && wbl_optreal(L, 2, "bend", &d.bend) && d.bend < 0)
        return wbl_fielderror(L, 2, "bend", "compliance must be >= 0");
    lua_pop(L, 1);
    /* bend_links (skip-one distance links): nil/false = none, true = as stiff as the
     * links, a number = their compliance */
    lua_getfield(L, 2, "bend_links");
    if (lua_isboolean(L, -1)) d.bend_links = lua_toboolean(L, -1) ? d.link.compliance : -1;
    else if (!lua_isnil(L, -1) && wbl_optreal(L, 2, "bend_links", &d.bend_links) && d.bend_links < 0)
        return wbl_fielderror(L, 2, "bend_links", "compliance must be >= 0");
    lua_pop(L, 1);
    check_link(L, &d.link);
    /* refuse absurd sizes before the core allocates anything */
    if ((int64_t)d.res[0] * d.res[1] > WB_MAX_PARTICLES)
        return wbl_fielderror(L, 2, "res", "%d x %d particles is too many (limit %d)", d.res[0], d.res[1],
                              (int)WB_MAX_PARTICLES);
    BUILD(L, w, wb_cloth, "cloth", (int64_t)d.res[0] * d.res[1]);
}

static const char *const rope_keys[] = {
    "from", "to", "segments", "mass", "radius",
    "compliance", "damping", "yield", "creep", "break_strain", "break_force", "collide", "self_collide", "friction",
    "material", NULL
};

static int w_rope(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    wb_rope_def d = wb_rope_default_def();
    wbl_checkopts(L, 2, rope_keys, false);
    wbl_optvec(L, 2, "from", 3, d.from);
    wbl_optvec(L, 2, "to", 3, d.to);
    wbl_optint(L, 2, "segments", 1, WB_MAX_PARTICLES - 1, &d.segments);
    /* a preset: a rod of its diameter (area A), segments of length l: mass rho A L, links
     * of stiffness E A / l and dashpots eta A / l */
    const wb_material *mat = wbl_opt_material(L, 2);
    if (mat) {
        const wb_real dx = d.to[0] - d.from[0], dy = d.to[1] - d.from[1], dz = d.to[2] - d.from[2];
        const wb_real len = sqrt(dx * dx + dy * dy + dz * dz), l = len / d.segments;
        const wb_real area = 3.14159265358979323846 / 4 * mat->thickness * mat->thickness;
        if (len > 0) d.mass = mat->density * area * len;
        if (l > 0) {
            d.link.compliance = l / (mat->young * area);
            d.link.damping = mat->viscosity * area / l;
        }
    }
    const bool auto_radius = read_mass_radius(L, &d.mass, &d.radius);
    wbl_contact_opts co;
    wbl_read_contact_opts(L, 2, &co);
    wbl_material_friction(L, 2, mat, &co);
    wbl_read_link(L, 2, &d.link);
    check_link(L, &d.link);
    BUILD(L, w, wb_rope, "rope", (int64_t)d.segments + 1);
}

static const char *const lattice_keys[] = {
    "min", "max", "res", "mass", "radius", "tets", "volume_compliance", "young", "poisson",
    "compliance", "damping", "yield", "creep", "break_strain", "break_force", "collide", "self_collide", "friction",
    "material", NULL
};

static int w_lattice(lua_State *L)
{
    wb_world *w = wbl_checkworld(L, 1);
    wb_lattice_def d = wb_lattice_default_def();
    wbl_checkopts(L, 2, lattice_keys, false);
    wbl_optvec(L, 2, "min", 3, d.min);
    wbl_optvec(L, 2, "max", 3, d.max);
    if (!(d.min[0] < d.max[0] && d.min[1] < d.max[1] && d.min[2] < d.max[2]))
        return luaL_argerror(L, 2, "min must be below max on every axis");
    wbl_optivec(L, 2, "res", 3, 2, WB_MAX_PARTICLES, d.res);
    /* a preset: mass rho x the box's volume; Neo-Hookean tets of its E and nu (tets on
     * unless the options say false) with dashpots eta a on the cell's links (a the mean
     * cell edge: a cubic grid's edge dashpots alone give a viscosity eta, the diagonals
     * add to it); with tets = false links of stiffness E a */
    const wb_material *mat = wbl_opt_material(L, 2);
    if (mat) d.tets = true;
    /* tets: 6 per cell, each with a volume constraint of compliance volume_compliance
     * (m^3/Pa, default 0: incompressible; `compliance` stays the links' own, in m/N) */
    wbl_optbool(L, 2, "tets", &d.tets);
    if (mat) {
        wb_real vol = 1, a = 0;
        for (int k = 0; k < 3; k++) {
            vol *= d.max[k] - d.min[k];
            a += (d.max[k] - d.min[k]) / (d.res[k] - 1) / 3;
        }
        d.mass = mat->density * vol;
        if (d.tets) {
            d.young = mat->young;
            d.poisson = mat->poisson;
        } else d.link.compliance = 1 / (mat->young * a);
        d.link.damping = mat->viscosity * a;
    }
    const bool auto_radius = read_mass_radius(L, &d.mass, &d.radius);
    wbl_contact_opts co;
    wbl_read_contact_opts(L, 2, &co);
    wbl_material_friction(L, 2, mat, &co);
    if (wbl_optreal(L, 2, "volume_compliance", &d.volume_compliance) && d.volume_compliance < 0)
        return wbl_fielderror(L, 2, "volume_compliance", "must be >= 0");
    /* young (Pa): Neo-Hookean tets (lua/volume.c's w:tet) and no links, so that E means E */
    wbl_read_neo(L, 2, &d.young, &d.poisson);
    if (d.young > 0 && !d.tets) return wbl_fielderror(L, 2, "young", "needs tets = true");
    /* the compliance of the tets' volume constraints: meaningless without tets */
    const int has_vc = lua_getfield(L, 2, "volume_compliance") != LUA_TNIL;
    lua_pop(L, 1);
    if (has_vc && !d.tets) return wbl_fielderror(L, 2, "volume_compliance", "needs tets = true");
    wbl_read_link(L, 2, &d.link);
    check_link(L, &d.link);
    if ((int64_t)d.res[0] * d.res[1] * d.res[2] > WB_MAX_PARTICLES)
        return wbl_fielderror(L, 2, "res", "%d x %d x %d particles is too many (limit %d)", d.res[0], d.res[1],
                              d.res[2], (int)WB_MAX_PARTICLES);
    /* BUILD, plus body.tet_count as the other tet bodies have it */
    wb_body b;
    wbl_body_begin(L, (int64_t)d.res[0] * d.res[1] * d.res[2]);
    const int32_t nd0 = wb_distance_count(w), nv0 = wb_volume_count(w) + wb_tet_count(w);
    wb_status st = wb_lattice(w, &d, &b);
    if (st != WB_OK) return wbl_status_error(L, 2, st, "lattice");
    if (auto_radius) wbl_default_radius(w, b);
    wbl_apply_contact_opts(w, b, &co);
    wbl_body_end(L, 1, b, wb_distance_count(w) - nd0);
    if (d.tets) {
        lua_pushinteger(L, wb_volume_count(w) + wb_tet_count(w) - nv0);
        lua_setfield(L, -2, "tet_count");
    }
    return 1;
}

static const luaL_Reg body_methods[] = {
    { "pin_where", body_pin_where },
    { "pin_all", body_pin_all },
    { "unpin_all", body_unpin_all },
    { NULL, NULL }
};

static const luaL_Reg world_methods[] = {
    { "cloth", w_cloth },
    { "rope", w_rope },
    { "lattice", w_lattice },
    { NULL, NULL }
};

void wbl_open_body(lua_State *L)
{
    luaL_newmetatable(L, WBL_BODY);
    luaL_newlibtable(L, body_methods);
    luaL_setfuncs(L, body_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pushcfunction(L, body_tostring);
    lua_setfield(L, -2, "__tostring");
    lua_pop(L, 1);
    wbl_add_world_methods(L, world_methods);
}
