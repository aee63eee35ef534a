/* plot.c: w:run{..., plot = "energy.png"}: a sampler kept on w:run's stack,
 * fed after every frame and written as a PNG chart when the run ends. world.c
 * calls the three functions below; the path is checked before the first frame. */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util.h"
#include "render/render.h"
#include "sandbox.h"

#define WBL_PLOT "wobble.plot"
#define PLOT_W 960
#define PLOT_H 720

typedef struct wbl_plot {
    wb_plot *p;
    char path[PATH_MAX];
    char name[64];   /* the title: the file name the script gave */
} wbl_plot;

static int plot_gc(lua_State *L)
{
    wbl_plot *u = (wbl_plot *)luaL_checkudata(L, 1, WBL_PLOT);
    wb_plot_destroy(u->p);
    u->p = NULL;
    return 0;
}

void wbl_plot_push(lua_State *L, int opts, const char *key, int world)
{
    opts = lua_absindex(L, opts);
    world = lua_absindex(L, world);
    if (lua_getfield(L, opts, key) == LUA_TNIL) return;   /* nil stays in the slot */
    if (lua_type(L, -1) != LUA_TSTRING)
        wbl_fielderror(L, opts, key, "file name expected, got %s", luaL_typename(L, -1));
    const char *given = lua_tostring(L, -1), *e = strrchr(given, '.');
    if (!e || strcmp(e, ".png") != 0) wbl_fielderror(L, opts, key, "a .png file name expected, got '%s'", given);
    wbl_plot *u = (wbl_plot *)lua_newuserdatauv(L, sizeof *u, 0);
    u->p = NULL;
    luaL_setmetatable(L, WBL_PLOT);
    const char *err;
    if (!wb_sandbox_path(L, given, 1, u->path, sizeof u->path, &err)) luaL_error(L, "%s", err);
    const char *slash = strrchr(given, '/');
    snprintf(u->name, sizeof u->name, "%s", slash ? slash + 1 : given);
    u->p = wb_plot_create();
    if (!u->p) wb_rt_budget_error(L, "out of memory for a plot");
    lua_replace(L, -2);   /* the sampler replaces the path */
    wbl_plot_frame(L, -1, world);   /* the state before the first frame */
}

void wbl_plot_frame(lua_State *L, int plot, int world)
{
    wbl_plot *u = (wbl_plot *)luaL_testudata(L, plot, WBL_PLOT);
    if (!u || !u->p) return;
    wb_world *w = wbl_checkworld(L, world);
    if (!wb_plot_sample(u->p, w)) wb_rt_budget_error(L, "out of memory for the plot's samples");
}

void wbl_plot_finish(lua_State *L, int plot)
{
    wbl_plot *u = (wbl_plot *)luaL_testudata(L, plot, WBL_PLOT);
    if (!u || !u->p) return;
    char title[128], err[PATH_MAX + 128];
    snprintf(title, sizeof title, "wobble: %s", u->name);
    uint8_t *px = wb_plot_render(u->p, PLOT_W, PLOT_H, title);
    wb_plot_destroy(u->p);
    u->p = NULL;
    if (!px) wb_rt_budget_error(L, "out of memory drawing the plot");
    bool ok = wbl_write_png(u->path, px, PLOT_W, PLOT_H, err, sizeof err);
    free(px);
    if (!ok) luaL_error(L, "plot: %s", err);
}

void wbl_open_plot(lua_State *L)
{
    luaL_newmetatable(L, WBL_PLOT);
    lua_pushcfunction(L, plot_gc);
    lua_setfield(L, -2, "__gc");
    lua_pop(L, 1);
}
