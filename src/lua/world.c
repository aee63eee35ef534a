/* world.c: the world userdata (wobble.world{...}) and its methods: particles,
 * settings, stepping, w:run and the queries. Constraint, collider and builder
 * methods are added to the same method table by their own files. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "util.h"
#include "render/render.h"

static const char *const solver_names[] = { "gauss-seidel", "jacobi", "vbd", NULL };

#define toworld(L) wbl_checkworld(L, 1)

/* ---- settings --------------------------------------------------------------------- */
static const char *const world_keys[] = {
    "gravity", "dt", "substeps", "iterations", "damping", "solver", "relaxation", "threads", "contacts",
    "max_depenetration", "tolerance", NULL
};

/* read the settings table at arg over *d; the core's check gives the ranges */
static void read_world_def(lua_State *L, int arg, wb_world_def *d)
{
    wbl_optvec(L, arg, "gravity", 3, d->gravity);
    wbl_optreal(L, arg, "dt", &d->dt);
    wbl_optint(L, arg, "substeps", INT32_MIN, INT32_MAX, &d->substeps);
    wbl_optint(L, arg, "iterations", INT32_MIN, INT32_MAX, &d->iterations);
    wbl_optreal(L, arg, "damping", &d->damping);
    int s = wbl_optenum(L, arg, "solver", "solver", solver_names);
    if (s >= 0) d->solver = (wb_solver)s;
    wbl_optreal(L, arg, "relaxation", &d->relaxation);
    wbl_optint(L, arg, "threads", INT32_MIN, INT32_MAX, &d->threads);
    wbl_optbool(L, arg, "contacts", &d->contacts);
    wbl_optreal(L, arg, "max_depenetration", &d->max_depenetration);
    wbl_optreal(L, arg, "tolerance", &d->tolerance);
}

/* check *d and apply it: errors blame argument `arg` */
static void apply_def(lua_State *L, wb_world *w, const wb_world_def *d, int arg)
{
    const char *err = wb_world_def_check(d);
    if (err) luaL_argerror(L, arg, err);
    wb_status st = wb_world_set_def(w, d);
    if (st != WB_OK) wbl_status_error(L, arg, st, "world settings");
}

int wbl_world_new(lua_State *L)
{
    wb_world_def d = wb_world_default_def();
    wbl_checkopts(L, 1, world_keys, true);
    /* --threads on the command line is the default a script can still override */
    wb_runtime *rt = wb_rt_get(L);
    if (rt && rt->threads > 0) d.threads = rt->threads;
    /* $WOBBLE_SOLVER likewise (run the same tests under another solver) */
    if (rt && rt->solver > 0) d.solver = (wb_solver)(rt->solver - 1);
    /* the world's arrays live outside the Lua heap: charge them to the same budget */
    if (rt) d.memory = &rt->memory;
    if (!lua_isnoneornil(L, 1)) read_world_def(L, 1, &d);
    const char *err = wb_world_def_check(&d);
    if (err) return luaL_argerror(L, 1, err);
    /* the userdata first: if Lua runs out of memory nothing leaks */
    wbl_world *ud = (wbl_world *)lua_newuserdatauv(L, sizeof *ud, 0);
    ud->w = NULL;
    ud->warned = 0;
    luaL_setmetatable(L, WBL_WORLD);
    ud->w = wb_world_create(&d);
    /* the world itself and its worker threads are charged too (hundreds of bytes; 32 kB a thread) */
    if (!ud->w) return wbl_status_error(L, 1, WB_ERR_NOMEM, "creating a world");
    return 1;
}

static int w_set_gravity(lua_State *L)
{
    wb_world *w = toworld(L);
    wb_world_def d = wb_world_get_def(w);
    wbl_checkreals(L, 2, 3, d.gravity);
    apply_def(L, w, &d, 2);
    return 0;
}

static int w_gravity(lua_State *L)
{
    wb_world_def d = wb_world_get_def(toworld(L));
    wbl_pushreals(L, d.gravity, 3);
    return 3;
}

/* the scalar settings: one getter and one setter each, generated */
#define REAL_SETTING(name)                                                        \
    static int w_set_##name(lua_State *L)                                         \
    {                                                                             \
        wb_world *w = toworld(L);                                                 \
        wb_world_def d = wb_world_get_def(w);                                     \
        d.name = wbl_checkreal(L, 2);                                             \
        apply_def(L, w, &d, 2);                                                   \
        return 0;                                                                 \
    }                                                                             \
    static int w_##name(lua_State *L)                                             \
    {                                                                             \
        lua_pushnumber(L, (lua_Number)wb_world_get_def(toworld(L)).name);         \
        return 1;                                                                 \
    }
#define INT_SETTING(name)                                                         \
    static int w_set_##name(lua_State *L)                                         \
    {                                                                             \
        wb_world *w = toworld(L);                                                 \
        wb_world_def d = wb_world_get_def(w);                                     \
        lua_Integer v = wbl_checkint(L, 2);                                       \
        d.name = v < INT32_MIN ? INT32_MIN : v > INT32_MAX ? INT32_MAX : (int)v;  \
        apply_def(L, w, &d, 2);                                                   \
        return 0;                                                                 \
    }                                                                             \
    static int w_##name(lua_State *L)                                             \
    {                                                                             \
        lua_pushinteger(L, wb_world_get_def(toworld(L)).name);                    \
        return 1;                                                                 \
    }
REAL_SETTING(dt)
REAL_SETTING(damping)
REAL_SETTING(relaxation)
REAL_SETTING(tolerance)
INT_SETTING(substeps)
INT_SETTING(iterations)
INT_SETTING(threads)

static int w_set_solver(lua_State *L)
{
    wb_world *w = toworld(L);
    wb_world_def d = wb_world_get_def(w);
    d.solver = (wb_solver)wbl_enum_index(L, 2, luaL_checkstring(L, 2), "solver", solver_names);
    apply_def(L, w, &d, 2);
    return 0;
}

static int w_solver(lua_State *L)
{
    wb_world_def d = wb_world_get_def(toworld(L));
    lua_pushstring(L, solver_names[d.solver]);
    return 1;
}

/* ---- particles ---------------------------------------------------------------------- */
static const char *const particle_keys[] = { "pos", "vel", "mass", "radius", "group", "friction", NULL };

static int w_particle(lua_State *L)
{
    wb_world *w = toworld(L);
    wb_real pos[3] = { 0, 0, 0 }, vel[3] = { 0, 0, 0 }, mass = 1, radius = 0.02;
    wbl_checkopts(L, 2, particle_keys, false);
    if (!wbl_optvec(L, 2, "pos", 3, pos)) return wbl_fielderror(L, 2, "pos", "missing ({x,y,z} expected)");
    wbl_optvec(L, 2, "vel", 3, vel);
    if (wbl_optreal(L, 2, "mass", &mass) && mass < 0) return wbl_fielderror(L, 2, "mass", "must be >= 0");
    if (wbl_optreal(L, 2, "radius", &radius) && radius < 0) return wbl_fielderror(L, 2, "radius", "must be >= 0");
    /* group 0: loose, collides with every particle; a group > 0 joins that body */
    lua_Integer group = 0;
    wbl_optinteger(L, 2, "group", 0, WB_MAX_GROUP, &group);
    wb_real mu = 0;
    if (wbl_optreal(L, 2, "friction", &mu) && !(mu >= 0 && isfinite(mu)))
        return wbl_fielderror(L, 2, "friction", "must be a finite number >= 0");
    int32_t id = wb_particle_add(w, pos, vel, mass, radius);
    if (id < 0) return wbl_status_error(L, 2, (wb_status)id, "particle");
    wb_particle_set_group(w, id, (int32_t)group);
    wb_particle_set_friction(w, id, mu);
    lua_pushinteger(L, (lua_Integer)id + 1);
    return 1;
}

static int w_particle_count(lua_State *L)
{
    lua_pushinteger(L, wb_particle_count(toworld(L)));
    return 1;
}

static int w_position(lua_State *L)
{
    wb_world *w = toworld(L);
    wb_real x[3];
    wb_particle_position(w, wbl_checkparticle(L, w, 2), x);
    wbl_pushreals(L, x, 3);
    return 3;
}

static int w_set_position(lua_State *L)
{
    wb_world *w = toworld(L);
    int32_t p = wbl_checkparticle(L, w, 2);
    wb_real x[3];
    wbl_checkreals(L, 3, 3, x);
    wb_particle_set_position(w, p, x);
    return 0;
}

static int w_velocity(lua_State *L)
{
    wb_world *w = toworld(L);
    wb_real v[3];
    wb_particle_velocity(w, wbl_checkparticle(L, w, 2), v);
    wbl_pushreals(L, v, 3);
    return 3;
}

static int w_set_velocity(lua_State *L)
{
    wb_world *w = toworld(L);
    int32_t p = wbl_checkparticle(L, w, 2);
    wb_real v[3];
    wbl_checkreals(L, 3, 3, v);
    wb_particle_set_velocity(w, p, v);
    return 0;
}

static int w_mass(lua_State *L)
{
    wb_world *w = toworld(L);
    lua_pushnumber(L, (lua_Number)wb_particle_mass(w, wbl_checkparticle(L, w, 2)));
    return 1;
}

static int w_radius(lua_State *L)
{
    wb_world *w = toworld(L);
    lua_pushnumber(L, (lua_Number)wb_particle_radius(w, wbl_checkparticle(L, w, 2)));
    return 1;
}

/* w:friction(p) -> the contact friction of particle p (a builder's, or its preset's) */
static int w_friction(lua_State *L)
{
    wb_world *w = toworld(L);
    lua_pushnumber(L, (lua_Number)wb_particle_friction(w, wbl_checkparticle(L, w, 2)));
    return 1;
}

static int w_pin(lua_State *L)
{
    wb_world *w = toworld(L);
    int32_t p = wbl_checkparticle(L, w, 2);
    wb_real at[3];
    bool has_at = !lua_isnoneornil(L, 3);
    if (has_at) wbl_checkvec(L, 3, 3, at);
    wb_particle_pin(w, p, has_at ? at : NULL);
    return 0;
}

static int w_unpin(lua_State *L)
{
    wb_world *w = toworld(L);
    wb_particle_unpin(w, wbl_checkparticle(L, w, 2));
    return 0;
}

static int w_pinned(lua_State *L)
{
    wb_world *w = toworld(L);
    lua_pushboolean(L, wb_particle_pinned(w, wbl_checkparticle(L, w, 2)));
    return 1;
}

/* ---- stepping ------------------------------------------------------------------------ */
static int w_step(lua_State *L)
{
    wbl_step(L, toworld(L));
    wbl_after_frame(L, 1);
    return 0;
}

/* the state of a w:run, kept on the stack so on_frame may yield (lua_callk); as a
 * to-be-closed value it also ends the progress bar on return or on error */
#define WBL_RUN "wobble.run_state"
typedef struct run_state {
    int active;          /* the progress bar is open */
    int has_fn;          /* on_frame given (stack slot 3) */
    int64_t n, done;
} run_state;

static int run_close(lua_State *L)
{
    run_state *r = (run_state *)luaL_checkudata(L, 1, WBL_RUN);
    if (r->active) {
        r->active = 0;
        wb_progress_end(L);
    }
    return 0;
}

/* the value on_frame returned (popped): `return false` stops the run */
static bool run_stops(lua_State *L)
{
    bool stop = lua_isboolean(L, -1) && !lua_toboolean(L, -1);
    lua_pop(L, 1);
    return stop;
}

/* stack: 1 world, 2 options, 3 on_frame or nil, 4 run state, 5 plot sampler or nil */
static int run_loop(lua_State *L, int status, lua_KContext ctx)
{
    run_state *r = (run_state *)lua_touserdata(L, 4);
    (void)ctx;
    if (status == LUA_YIELD && run_stops(L)) goto done; /* resumed after on_frame yielded */
    while (r->done < r->n) {
        wb_world *w = toworld(L); /* on_frame may have closed it */
        wbl_step(L, w);
        r->done++;
        wbl_after_frame(L, 1);
        wbl_plot_frame(L, 5, 1);
        wb_progress_update(L, r->done);
        if (r->has_fn) {
            lua_pushvalue(L, 3);
            lua_pushvalue(L, 1);
            lua_pushinteger(L, (lua_Integer)wb_world_frame(w));
            lua_pushnumber(L, wb_world_time(w));
            lua_callk(L, 3, 1, 0, run_loop);
            if (run_stops(L)) break;
        }
    }
done:
    wbl_plot_finish(L, 5);   /* plot = "x.png": the chart of the run */
    lua_closeslot(L, 4);
    lua_pushinteger(L, (lua_Integer)r->done);
    return 1;
}

static const char *const run_keys[] = { "frames", "seconds", "on_frame", "plot", NULL };

static int w_run(lua_State *L)
{
    wb_world *w = toworld(L);
    wbl_checkopts(L, 2, run_keys, false);
    int64_t n;
    wb_real seconds;
    lua_Integer frames = 0;
    bool has_frames = wbl_optinteger(L, 2, "frames", 0, LUA_MAXINTEGER, &frames);
    bool has_seconds = wbl_optreal(L, 2, "seconds", &seconds);
    if (has_frames == has_seconds)
        return luaL_argerror(L, 2, "exactly one of 'frames' or 'seconds' expected");
    if (has_seconds) {
        if (seconds < 0) return wbl_fielderror(L, 2, "seconds", "must be >= 0");
        double f = nearbyint(seconds / wb_world_get_def(w).dt);
        if (f > 1e15) return wbl_fielderror(L, 2, "seconds", "too many frames");
        n = (int64_t)f;
    } else {
        n = frames;
    }
    lua_getfield(L, 2, "on_frame");
    bool has_fn = !lua_isnil(L, -1);
    if (has_fn && !lua_isfunction(L, -1) && !luaL_getmetafield(L, -1, "__call"))
        wbl_fielderror(L, 2, "on_frame", "function expected, got %s", luaL_typename(L, -1));
    lua_settop(L, 3);
    /* --frames N on the command line caps every run */
    wb_runtime *rt = wb_rt_get(L);
    if (rt && rt->frame_cap >= 0 && n > rt->frame_cap) n = rt->frame_cap;

    run_state *r = (run_state *)lua_newuserdatauv(L, sizeof *r, 0);
    memset(r, 0, sizeof *r);
    luaL_setmetatable(L, WBL_RUN);
    lua_toclose(L, 4);
    r->n = n;
    r->has_fn = has_fn;
    wbl_plot_push(L, 2, "plot", 1);   /* slot 5: the plot's sampler, or nil */
    r->active = 1;
    wb_progress_begin(L, "run", n, wb_rt_get(L)->quiet);
    return run_loop(L, LUA_OK, 0);
}

static int w_time(lua_State *L)
{
    lua_pushnumber(L, wb_world_time(toworld(L)));
    return 1;
}

static int w_frame(lua_State *L)
{
    lua_pushinteger(L, (lua_Integer)wb_world_frame(toworld(L)));
    return 1;
}

/* ---- queries ---------------------------------------------------------------------------- */
static int w_energy(lua_State *L)
{
    wb_real k, p;
    wb_world_energy(toworld(L), &k, &p);
    lua_pushnumber(L, k);
    lua_pushnumber(L, p);
    return 2;
}

static int w_momentum(lua_State *L)
{
    wb_real m[3];
    wb_world_momentum(toworld(L), m);
    wbl_pushreals(L, m, 3);
    return 3;
}

static int w_angular_momentum(lua_State *L)
{
    wb_real m[3];
    wb_world_angular_momentum(toworld(L), m);
    wbl_pushreals(L, m, 3);
    return 3;
}

static int w_bounds(lua_State *L)
{
    wb_real lo[3], hi[3];
    if (!wb_world_bounds(toworld(L), lo, hi)) {
        lua_pushnil(L);
        return 1;
    }
    wbl_pushreals(L, lo, 3);
    wbl_pushreals(L, hi, 3);
    return 6;
}

static int w_max_strain(lua_State *L)
{
    lua_pushnumber(L, wb_world_max_strain(toworld(L)));
    return 1;
}

/* w:group(p) -> its contact group (0 = loose) */
static int w_group(lua_State *L)
{
    wb_world *w = toworld(L);
    lua_pushinteger(L, wb_particle_group(w, wbl_checkparticle(L, w, 2)));
    return 1;
}

/* w:set_self_collide(group | body, bool): whether a body collides with itself (a body
 * table, as the builders return it, stands for its group) */
static int w_set_self_collide(lua_State *L)
{
    wb_world *w = toworld(L);
    if (lua_type(L, 2) == LUA_TTABLE) {
        if (lua_getfield(L, 2, "group") != LUA_TNUMBER || !lua_isinteger(L, -1))
            return luaL_argerror(L, 2, "group or body expected (the table has no integer 'group')");
        lua_replace(L, 2);
    }
    lua_Integer g = wbl_checkint(L, 2);
    if (g < 1 || g > WB_MAX_GROUP) return luaL_argerror(L, 2, "group must be a body's group (>= 1)");
    luaL_checktype(L, 3, LUA_TBOOLEAN);
    /* a group no particle is in: a slip (particles joining it later are not changed) */
    if (wb_group_set_self_collide(w, (int32_t)g, lua_toboolean(L, 3)) == 0)
        return luaL_argerror(L, 2, lua_pushfstring(L, "no particle is in group %I", g));
    return 0;
}

/* the stats table's residual, worked out when read (a pass over every constraint: a
 * script reading the step's time every frame does not pay for it) */
static int stats_index(lua_State *L)
{
    const char *k = lua_tostring(L, 2);
    if (k && !strcmp(k, "residual")) {
        lua_pushnumber(L, (lua_Number)wb_world_residual(wbl_checkworld(L, lua_upvalueindex(1))));
        return 1;
    }
    return 0;
}

static int w_stats(lua_State *L)
{
    wb_world *w = toworld(L);
    wb_stats s = wb_world_stats(w);
    wb_world_def d = wb_world_get_def(w);
    lua_createtable(L, 0, 20);
#define SETI(name, v) (lua_pushinteger(L, (lua_Integer)(v)), lua_setfield(L, -2, name))
#define SETN(name, v) (lua_pushnumber(L, (lua_Number)(v)), lua_setfield(L, -2, name))
    SETI("particles", s.particles);
    SETI("distances", s.distances);
    SETI("broken", s.broken);
    SETI("colliders", s.colliders);
    SETI("bends", s.bends);
    SETI("volumes", s.volumes);
    SETI("tets", s.tets);
    SETI("shape_matches", s.shape_matches);
    SETI("pressures", s.pressures);
    SETI("attachments", s.attachments);
    SETI("grabs", s.grabs);
    SETI("colours", s.colours);
    SETI("contacts", s.contacts);
    SETI("particle_contacts", s.particle_contacts);
    SETI("rigids", s.rigids);
    SETI("rigid_contacts", s.rigid_contacts);
    SETI("tethers", s.tethers);
    SETN("broad_ms", s.broad_ms);
    SETN("broad_remakes", s.broad_remakes);
    SETI("projections", s.projections);
    SETN("step_ms", s.step_ms);
    SETN("solve_ms", s.solve_ms);
    SETI("warnings", s.warnings);
    SETI("substeps", d.substeps);
    SETI("iterations", d.iterations);
    SETN("iterations_run", s.iterations_run);
    SETI("threads", d.threads);
    SETN("dt", d.dt);
    lua_pushstring(L, solver_names[d.solver]);
    lua_setfield(L, -2, "solver");
    lua_createtable(L, 0, 1);
    lua_pushvalue(L, 1);
    lua_pushcclosure(L, stats_index, 1);
    lua_setfield(L, -2, "__index");
    lua_setmetatable(L, -2);
#undef SETI
#undef SETN
    return 1;
}

/* w:contacts() -> { {a =, b =, force =, normal = {x, y, z}, kind =}, ... }: the particle-particle
 * contacts (kind "particle"), then the particle-triangle ones (kind "triangle"), that
 * corrected positions in the last substep (wobble.h: wb_world_contact_at, wb_world_tri_contact_at);
 * particle ids from 1 */
static int w_contacts(lua_State *L)
{
    wb_world *w = toworld(L);
    const int32_t n = wb_world_contact_count(w);
    lua_createtable(L, n, 0);
    for (int32_t i = 0; i < n; i++) {
        const wb_contact c = wb_world_contact_at(w, i);
        lua_createtable(L, 0, 5);
        lua_pushinteger(L, (lua_Integer)c.a + 1);
        lua_setfield(L, -2, "a");
        lua_pushinteger(L, (lua_Integer)c.b + 1);
        lua_setfield(L, -2, "b");
        lua_pushnumber(L, (lua_Number)c.force);
        lua_setfield(L, -2, "force");
        lua_pushnumber(L, (lua_Number)c.depth);
        lua_setfield(L, -2, "depth");
        lua_createtable(L, 3, 0);
        for (int k = 0; k < 3; k++) {
            lua_pushnumber(L, (lua_Number)c.normal[k]);
            lua_rawseti(L, -2, k + 1);
        }
        lua_setfield(L, -2, "normal");
        lua_pushliteral(L, "particle");
        lua_setfield(L, -2, "kind");
        lua_rawseti(L, -2, i + 1);
    }
    /* then the particle-triangle contacts: a = the particle, b = the triangle's first
     * corner, kind = "triangle", triangle = its corners, bary = the closest point's weights */
    const int32_t nt = wb_world_tri_contact_count(w);
    for (int32_t i = 0; i < nt; i++) {
        const wb_tri_contact c = wb_world_tri_contact_at(w, i);
        lua_createtable(L, 0, 8);
        lua_pushinteger(L, (lua_Integer)c.p + 1);
        lua_setfield(L, -2, "a");
        lua_pushinteger(L, (lua_Integer)c.tri[0] + 1);
        lua_setfield(L, -2, "b");
        lua_pushnumber(L, (lua_Number)c.force);
        lua_setfield(L, -2, "force");
        lua_pushnumber(L, (lua_Number)c.depth);
        lua_setfield(L, -2, "depth");
        lua_pushliteral(L, "triangle");
        lua_setfield(L, -2, "kind");
        const char *const vec[3] = { "normal", "triangle", "bary" };
        for (int f = 0; f < 3; f++) {
            lua_createtable(L, 3, 0);
            for (int k = 0; k < 3; k++) {
                if (f == 1) lua_pushinteger(L, (lua_Integer)c.tri[k] + 1);
                else lua_pushnumber(L, (lua_Number)(f == 0 ? c.normal[k] : c.bary[k]));
                lua_rawseti(L, -2, k + 1);
            }
            lua_setfield(L, -2, vec[f]);
        }
        lua_rawseti(L, -2, n + i + 1);
    }
    return 1;
}

static int w_hash(lua_State *L)
{
    char buf[17];
    snprintf(buf, sizeof buf, "%016" PRIx64, wb_world_hash(toworld(L)));
    lua_pushstring(L, buf);
    return 1;
}

static int w_warnings(lua_State *L)
{
    wb_world *w = toworld(L);
    lua_pushinteger(L, (lua_Integer)wb_world_warnings(w));
    const char *msg = wb_world_last_warning(w);
    if (msg && *msg) lua_pushstring(L, msg);
    else lua_pushnil(L);
    return 2;
}

/* ---- life cycle ------------------------------------------------------------------------- */
/* __gc, __close and w:close(): safe in any order and any number of times */
static int w_close(lua_State *L)
{
    wbl_world *ud = wbl_checkworld_ud(L, 1);
    wbl_result_world_closing(L, ud);   /* result.json's hash outlives the world */
    wb_world_destroy(ud->w);
    ud->w = NULL;
    return 0;
}

static int w_closed(lua_State *L)
{
    lua_pushboolean(L, wbl_checkworld_ud(L, 1)->w == NULL);
    return 1;
}

static int w_tostring(lua_State *L)
{
    wbl_world *ud = wbl_checkworld_ud(L, 1);
    if (!ud->w) lua_pushfstring(L, "wobble.world: %p (closed)", (void *)ud);
    else lua_pushfstring(L, "wobble.world: %p (%d particles)", (void *)ud, (int)wb_particle_count(ud->w));
    return 1;
}

static const luaL_Reg world_methods[] = {
    { "particle", w_particle },
    { "particle_count", w_particle_count },
    { "position", w_position },
    { "set_position", w_set_position },
    { "velocity", w_velocity },
    { "set_velocity", w_set_velocity },
    { "mass", w_mass },
    { "radius", w_radius },
    { "friction", w_friction },
    { "group", w_group },
    { "set_self_collide", w_set_self_collide },
    { "pin", w_pin },
    { "unpin", w_unpin },
    { "pinned", w_pinned },
    { "step", w_step },
    { "run", w_run },
    { "time", w_time },
    { "frame", w_frame },
    { "energy", w_energy },
    { "momentum", w_momentum },
    { "angular_momentum", w_angular_momentum },
    { "bounds", w_bounds },
    { "max_strain", w_max_strain },
    { "stats", w_stats },
    { "contacts", w_contacts },
    { "hash", w_hash },
    { "warnings", w_warnings },
    { "gravity", w_gravity },
    { "set_gravity", w_set_gravity },
    { "dt", w_dt },
    { "set_dt", w_set_dt },
    { "tolerance", w_tolerance },
    { "set_tolerance", w_set_tolerance },
    { "substeps", w_substeps },
    { "set_substeps", w_set_substeps },
    { "iterations", w_iterations },
    { "set_iterations", w_set_iterations },
    { "damping", w_damping },
    { "set_damping", w_set_damping },
    { "solver", w_solver },
    { "set_solver", w_set_solver },
    { "relaxation", w_relaxation },
    { "set_relaxation", w_set_relaxation },
    { "threads", w_threads },
    { "set_threads", w_set_threads },
    { "close", w_close },
    { "closed", w_closed },
    { NULL, NULL }
};

static const luaL_Reg world_meta[] = {
    { "__index", NULL }, /* the method table, set below */
    { "__gc", w_close },
    { "__close", w_close },
    { "__tostring", w_tostring },
    { NULL, NULL }
};

void wbl_add_world_methods(lua_State *L, const luaL_Reg *l)
{
    luaL_getmetatable(L, WBL_WORLD);
    lua_getfield(L, -1, "__index");
    luaL_setfuncs(L, l, 0);
    lua_pop(L, 2);
}

void wbl_open_world(lua_State *L)
{
    luaL_newmetatable(L, WBL_WORLD);
    luaL_setfuncs(L, world_meta, 0);
    luaL_newlibtable(L, world_methods);
    luaL_setfuncs(L, world_methods, 0);
    lua_setfield(L, -2, "__index");
    lua_pop(L, 1);
    luaL_newmetatable(L, WBL_RUN);
    lua_pushcfunction(L, run_close);
    lua_setfield(L, -2, "__close");
    lua_pushcfunction(L, run_close); /* a coroutine abandoned mid-run still ends its bar */
    lua_setfield(L, -2, "__gc");
    lua_pop(L, 1);
}
