/* input_driver.c: the input recorder (src/lua/input.h) driven as the viewer drives it,
 * for tests/cli/replay.sh: the recorder has no Lua entry point, so this program runs a
 * scene under the runtime with a frame hook that grabs, moves and releases through
 * wbl_input_* (after frames 10, 20, 30 and 45 of the first world), then saves the log.
 *   input_driver SCENE LOG [--set-like key=value]...   (the scene prints its hash)
 * Targets are offsets by thirds and sevenths from the particle's position, numbers that
 * only round-trip through the file when written with all their digits. It also checks
 * what the recorder refuses (a bad particle: false, nothing logged; a move after the
 * release: not logged) and prints "events N" and "refused: MESSAGE".
 * Exit 0 ok, 1 a check failed, 2 the scene or the log could not be had. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lua/input.h"
#include "lua/util.h"

static int check_failed;

static void expect(int ok, const char *what)
{
    if (!ok) {
        fprintf(stderr, "input_driver: check failed: %s\n", what);
        check_failed = 1;
    }
}

static int hook(lua_State *L)
{
    wbl_input_log *log = lua_touserdata(L, lua_upvalueindex(1));
    wb_grab_id *g = lua_touserdata(L, lua_upvalueindex(2));
    wb_world *w = wbl_checkworld(L, 1);
    const int world = wbl_input_world(L, 1);
    if (world != 1) return 0;
    const int64_t f = wb_world_frame(w), before = wbl_input_log_events(log);
    wb_real p[3];
    wb_particle_position(w, 20, p);
    char err[256];
    if (f == 10) {
        const wb_real bad[3] = { 0, 0, 0 };
        expect(!wbl_input_grab(log, w, world, wb_particle_count(w), bad, 0, NULL, err, sizeof err),
               "a grab of a particle past the last is refused");
        printf("refused: %s\n", err);
        expect(wbl_input_log_events(log) == before, "a refused grab is not logged");
        const wb_real t[3] = { p[0] + 1.0 / 3, p[1] + 2.0 / 7, p[2] + 1.0 / 9 };
        if (!wbl_input_grab(log, w, world, 20, t, 1.0 / 3000, g, err, sizeof err))
            return luaL_error(L, "input_driver: %s", err);
    } else if (f == 20 || f == 30) {
        const wb_real t[3] = { p[0] - 1.0 / 7, p[1] + 1.0 / 3, p[2] + (f == 20 ? 2.0 / 9 : -3.0 / 11) };
        wbl_input_move(log, w, world, *g, t);
    } else if (f == 45) {
        wbl_input_release(log, w, world, *g);
    } else if (f == 46) {
        const wb_real t[3] = { 0, 1, 0 };
        wbl_input_move(log, w, world, *g, t); /* released: nothing happens, nothing logged */
        wbl_input_release(log, w, world, *g);
        expect(wbl_input_log_events(log) == before, "a move or release of a released grab is not logged");
    }
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: input_driver SCENE LOG\n");
        return 2;
    }
    static char dir[4096];
    snprintf(dir, sizeof dir, "%s", argv[1]);
    char *slash = strrchr(dir, '/');
    if (slash) *slash = 0;
    else strcpy(dir, ".");
    wb_runtime cfg = { 0 };
    cfg.scene_dir = dir;
    cfg.out_dir = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    cfg.frame_cap = -1;
    cfg.quiet = 1;
    cfg.open_module = luaopen_wobble;
    cfg.script = argv[1];
    lua_State *L = wb_rt_open(&cfg);
    wbl_input_log *log = wbl_input_log_create();
    if (!L || !log) return 2;
    wb_grab_id g = { 0, 0 };
    lua_pushlightuserdata(L, log);
    lua_pushlightuserdata(L, &g);
    lua_pushcclosure(L, hook, 2);
    wb_rt_add_frame_hook(L, -1);
    lua_pop(L, 1);
    lua_getglobal(L, "wobble");
    lua_newtable(L); /* wobble.args: empty, the scene does no grab of its own */
    lua_setfield(L, -2, "args");
    lua_pop(L, 1);
    if (luaL_loadfile(L, argv[1]) != LUA_OK || lua_pcall(L, 0, 0, 0) != LUA_OK) {
        fprintf(stderr, "%s\n", lua_tostring(L, -1));
        return 2;
    }
    printf("events %lld\n", (long long)wbl_input_log_events(log));
    expect(wbl_input_log_events(log) == 4, "four events logged (grab, move, move, release)");
    char err[512];
    if (!wbl_input_log_save(log, argv[2], argv[1], err, sizeof err)) {
        fprintf(stderr, "input_driver: %s\n", err);
        return 2;
    }
    wbl_input_log_clear(log);
    expect(wbl_input_log_events(log) == 0, "a cleared log is empty");
    wbl_input_log_destroy(log);
    wb_rt_close(L);
    return check_failed;
}
