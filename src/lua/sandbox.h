/* sandbox.h: the sandbox's file rules for a script (lua/sandbox.c). The runtime owns
 * a wb_sandbox and opens it on its state; the binding resolves every path a script names
 * through wb_sandbox_path (or wbl_path / wbl_allow). */
#ifndef WB_LUA_SANDBOX_H
#define WB_LUA_SANDBOX_H
#include <limits.h>
#include <stddef.h>
#include <lua.h>

#define WB_SANDBOX_ROOTS 8

typedef struct wb_sandbox {
    int unsafe;                                 /* --unsafe: paths resolved, nothing refused */
    char cwd[PATH_MAX], scene[PATH_MAX], out[PATH_MAX], lib[PATH_MAX];  /* canonical; lib may be "" */
    char out_shown[PATH_MAX];                   /* the output folder as the user named it, for messages */
    char roots[WB_SANDBOX_ROOTS][PATH_MAX];     /* canonical folders a script may read */
    int nroots;
    char err[2 * PATH_MAX + 128];               /* the last refusal's message */
    /* told of every existing file a read resolves to (wobble view --watch); may be NULL */
    void (*on_read)(void *ud, const char *path);
    void *on_read_ud;
} wb_sandbox;

/* canonical folders from the configuration (relative to the current folder); -1 when a
 * path is too long or the current folder is gone */
int wb_sandbox_init(wb_sandbox *sb, const char *scene_dir, const char *out_dir, const char *lib_dir,
                    const char *project_root, int unsafe);
/* open the standard libraries on L: all of them when unsafe, else without process
 * control, bytecode or debug; file functions go through the rules either way. sb must
 * outlive L. Raises on memory errors (call it protected). */
void wb_sandbox_open(lua_State *L, wb_sandbox *sb);
/* Resolve a path a script names. write=0: the file is read (scene folder, assets
 * folders, output folder); write=1: it is written (only under the output folder; a
 * relative path is taken inside it; parent folders are created; a path through a
 * symbolic link to nothing is refused); write=2: the same for the name itself (its last
 * name not followed when it is a link: os.remove, os.rename). Returns buf, or NULL with
 * *err set to a message naming the path as given. A state without a sandbox: no rules.
 * The caller opens the file without following a link at its name (O_NOFOLLOW, or
 * io/file.c's writers). */
const char *wb_sandbox_path(lua_State *L, const char *path, int write, char *buf, size_t n, const char **err);
/* the file name at arg: a string without a zero byte, else an argument error. A number
 * is refused, not converted (as Lua's own functions would): a name is a string */
const char *wbl_checkfilename(lua_State *L, int arg);
/* the same, raising the message as a Lua error */
const char *wbl_path(lua_State *L, const char *path, int write, char *buf, size_t n);
/* wbio_allow_fn over the sandbox, ud = the lua_State: never raises (assimp calls it) */
int wbl_allow(void *ud, const char *path, int write, char *err, size_t errn);
#endif
