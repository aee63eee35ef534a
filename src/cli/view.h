/* view.h: `wobble view SCENE.lua`, the scene live in a window. main.c parses the options
 * and gives the viewer the means to open a scene's state (the same runtime and wobble.args
 * as `wobble run`) as callbacks. */
#ifndef WB_CLI_VIEW_H
#define WB_CLI_VIEW_H

#include <lua.h>
#include <stdbool.h>
#include <stdint.h>

typedef struct wb_view_opts {
    const char *scene;
    bool watch;                /* --watch: restart when the scene or a file it read is saved */
    const char *record_input;  /* --record-input FILE, or NULL */
    const char *screenshot;    /* --screenshot FILE.png: the window's last picture, at the end */
    int width, height;         /* --size WxH */
    int64_t frames;            /* --frames N: close when the scene ends (or after N frames); -1 none */
    /* a new state for the scene (sandbox, budgets, wobble.args): NULL with *err set */
    lua_State *(*open)(void *host, const char **err);
    void (*print_error)(const char *msg);   /* a script error on the terminal */
    void *host;
} wb_view_opts;

/* runs the viewer until Esc, the window is closed, or (--frames) the scene ends;
 * returns the exit code: 0, 2 (no display, a script error without --watch), 3 (budget) */
int wb_view_main(const wb_view_opts *o);
/* --watch: a file the scene read (wb_runtime.on_read), watched from now on */
void wb_view_file_read(void *ud, const char *path);

#endif
