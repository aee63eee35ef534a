/* sandbox.c: the file rules of the sandbox (a scene writes only under its output folder).
 * Every path a script names is made absolute and canonical (no ".." or symlink can leave a
 * folder unnoticed); reads are allowed under the scene, assets and output folders, writes
 * only under the output folder. A write through a symbolic link that leads nowhere is
 * refused (its target would be created wherever it points), and the files themselves are
 * opened without following a link at their name (io.open here; wobble's writers through
 * io/file.c), so a link placed in the output folder cannot take a write elsewhere. Refusals
 * name the path as the script gave it, never where it resolves. The standard libraries are
 * opened without process control, bytecode or debug, and their file functions are wrapped
 * to go through the same rules. */
#include "sandbox.h"

#include <lauxlib.h>
#include <lualib.h>

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char sandbox_key = 0;  /* registry: the wb_sandbox of this state */

static wb_sandbox *sb_from(lua_State *L) {
    lua_rawgetp(L, LUA_REGISTRYINDEX, &sandbox_key);
    wb_sandbox *sb = lua_touserdata(L, -1);
    lua_pop(L, 1);
    return sb;
}

/* ---- paths ----------------------------------------------------------------------------- */

static int join(char *out, size_t n, const char *dir, const char *path) {
    int k = path[0] == '/' ? snprintf(out, n, "%s", path)
                           : snprintf(out, n, "%s%s%s", dir, dir[strlen(dir) - 1] == '/' ? "" : "/", path);
    return k >= 0 && (size_t)k < n ? 0 : -1;
}

/* Canonical form of an absolute path: realpath of its longest existing prefix, then the
 * rest with "." and ".." applied by hand (a folder that does not exist yet cannot be a
 * symlink), so neither ".." nor a symlink can leave a folder unnoticed. */
static int canon(const char *abs, char *out) {
    char tmp[PATH_MAX];
    if (snprintf(tmp, sizeof tmp, "%s", abs) >= (int)sizeof tmp) return -1;
    size_t len = strlen(tmp), cut = len;
    for (;;) {
        char save = tmp[cut];
        tmp[cut] = 0;
        int ok = cut > 0 && realpath(tmp, out) != NULL;
        tmp[cut] = save;
        if (ok) break;
        while (cut > 0 && tmp[--cut] != '/') {}
        if (cut == 0) { strcpy(out, "/"); break; }
    }
    size_t olen = strlen(out);
    for (char *s = tmp + cut; *s;) {
        while (*s == '/') s++;
        char *e = s;
        while (*e && *e != '/') e++;
        size_t cl = (size_t)(e - s);
        if (cl == 0 || (cl == 1 && s[0] == '.')) {
        } else if (cl == 2 && s[0] == '.' && s[1] == '.') {
            while (olen > 1 && out[olen - 1] != '/') olen--;
            if (olen > 1) olen--;
            out[olen] = 0;
        } else {
            if (olen + cl + 2 > PATH_MAX) return -1;
            if (olen > 1) out[olen++] = '/';
            memcpy(out + olen, s, cl);
            olen += cl;
            out[olen] = 0;
        }
        s = e;
    }
    if (len > 1 && abs[len - 1] == '/' && olen > 1 && olen + 2 <= PATH_MAX) strcpy(out + olen, "/");
    return 0;
}

/* Does a component of the canonical path c exist as a symbolic link? canon() resolved
 * every link it could follow, so one left is a link to nothing: a write would create its
 * target, wherever that is. */
static int through_link(const char *c) {
    char p[PATH_MAX];
    if (snprintf(p, sizeof p, "%s", c) >= (int)sizeof p) return 1;
    for (char *s = p + 1;; s++) {
        if (*s != '/' && *s) continue;
        char save = *s;
        *s = 0;
        struct stat st;
        int r = lstat(p, &st);
        *s = save;
        if (r != 0) return 0;  /* nothing below exists */
        if (S_ISLNK(st.st_mode)) return 1;
        if (!save) return 0;
    }
}

/* canon() of the folder holding abs, then its last name as it is: the entry itself, a
 * link not followed (os.remove and os.rename act on a link, not on what it names) */
static int canon_entry(const char *abs, char *out) {
    char dir[PATH_MAX];
    const char *slash = strrchr(abs, '/'), *base = slash ? slash + 1 : abs;
    if (!slash || !*base || !strcmp(base, ".") || !strcmp(base, "..")) return canon(abs, out);
    snprintf(dir, sizeof dir, "%.*s", (int)(slash - abs + 1), abs);
    if (canon(dir, out)) return -1;
    size_t ol = strlen(out);
    if (ol > 1 && out[ol - 1] == '/') out[--ol] = 0;
    if (ol + strlen(base) + 2 > PATH_MAX) return -1;
    if (ol > 1) out[ol++] = '/';
    strcpy(out + ol, base);
    return 0;
}

static int under(const char *path, const char *root) {
    size_t rl = strlen(root);
    if (rl == 1 && root[0] == '/') return 1;
    return strncmp(path, root, rl) == 0 && (path[rl] == 0 || path[rl] == '/');
}

static int may_read(const wb_sandbox *sb, const char *path) {
    for (int i = 0; i < sb->nroots; i++)
        if (under(path, sb->roots[i])) return 1;
    return 0;
}

static int exists(const char *path) {
    struct stat st;
    return stat(path, &st) == 0;
}

/* mkdir -p of the folders above the last component (and of a path ending in '/') */
static int make_parents(char *path) {
    for (char *s = path + 1; *s; s++) {
        if (*s != '/') continue;
        *s = 0;
        int bad = mkdir(path, 0777) != 0 && errno != EEXIST;
        *s = '/';
        if (bad) return -1;
    }
    return 0;
}

const char *wb_sandbox_path(lua_State *L, const char *path, int write, char *buf, size_t n, const char **err) {
    wb_sandbox *sb = sb_from(L);
    char full[PATH_MAX], c[PATH_MAX];
    *err = NULL;
    if (!sb) {  /* no sandbox: no rules */
        if (snprintf(buf, n, "%s", path) >= (int)n) return *err = "path too long", NULL;
        return buf;
    }
    if (!*path) return *err = "empty path", NULL;
    if (write) {
        /* a relative path is taken inside the output folder; the messages name the
         * path as given and the folder as the user named it: where a link leads, or
         * the current folder, is not the script's to learn */
        if (join(full, sizeof full, sb->out, path) || (write == 2 ? canon_entry(full, c) : canon(full, c)))
            return *err = "path too long", NULL;
        if (!sb->unsafe && !under(c, sb->out)) {
            if (snprintf(sb->err, sizeof sb->err, "writing %s is outside the output folder %s; use --out DIR or --unsafe",
                         path, sb->out_shown) >= (int)sizeof sb->err)
                return *err = "writing outside the output folder; use --out DIR or --unsafe", NULL;
            return *err = sb->err, NULL;
        }
        if (!sb->unsafe && write != 2 && through_link(c)) {
            if (snprintf(sb->err, sizeof sb->err, "writing %s goes through a symbolic link to nothing, which could "
                         "lead outside the output folder %s; remove the link or use --unsafe", path, sb->out_shown)
                >= (int)sizeof sb->err)
                return *err = "writing through a symbolic link to nothing; remove the link or use --unsafe", NULL;
            return *err = sb->err, NULL;
        }
        /* never outside the output folder, not even with --unsafe: no surprise folders */
        if (under(c, sb->out) && make_parents(c)) {
            snprintf(sb->err, sizeof sb->err, "cannot create the folders of %s: %s", path, strerror(errno));
            return *err = sb->err, NULL;
        }
    } else {
        /* relative: the current folder, then the scene's folder, then the output folder */
        const char *bases[3] = { sb->cwd, sb->scene, sb->out };
        int nb = path[0] == '/' ? 1 : 3, found = 0;
        char refused[PATH_MAX] = "";
        for (int i = 0; i < nb && !found; i++) {
            if (join(full, sizeof full, bases[i], path) || canon(full, c)) return *err = "path too long", NULL;
            if (!exists(c)) continue;
            if (sb->unsafe || may_read(sb, c)) found = 1;
            else if (!refused[0]) strcpy(refused, c);
        }
        if (!found && refused[0]) strcpy(c, refused);
        /* nothing there: name the scene's folder, where the file was most likely meant to be */
        if (!found && !refused[0] && (join(full, sizeof full, nb == 1 ? "/" : sb->scene, path) || canon(full, c)))
            return *err = "path too long", NULL;
        if (!sb->unsafe && !may_read(sb, c)) {
            snprintf(sb->err, sizeof sb->err,
                     "reading %s is outside the allowed folders (scene, assets, out); use --unsafe", path);
            return *err = sb->err, NULL;
        }
        if (sb->on_read && exists(c)) sb->on_read(sb->on_read_ud, c);
    }
    if (snprintf(buf, n, "%s", c) >= (int)n) return *err = "path too long", NULL;
    return buf;
}

/* ---- the sandbox ------------------------------------------------------------------------- */

/* a path as error messages show it: relative to the current folder when inside it */
static const char *display(const wb_sandbox *sb, const char *path) {
    size_t cl = strlen(sb->cwd);
    if (under(path, sb->cwd) && path[cl] == '/' && cl > 1) return path + cl + 1;
    return path;
}

/* A file name must be a string. The io library would turn a number into a name itself,
 * after a check that only looked at strings (io.output(4242) made ./4242 anywhere), and
 * a zero byte would cut the name the rules see short of the name the caller meant. */
const char *wbl_checkfilename(lua_State *L, int arg) {
    size_t len;
    if (lua_type(L, arg) != LUA_TSTRING) luaL_typeerror(L, arg, "file name (a string)");
    const char *s = lua_tolstring(L, arg, &len);
    if (strlen(s) != len) luaL_argerror(L, arg, "file name contains a zero byte");
    return s;
}

/* replace the path argument at arg by its resolved form, or raise the rule's message */
static void check_arg(lua_State *L, int arg, int write) {
    char buf[PATH_MAX];
    const char *err, *p = wb_sandbox_path(L, wbl_checkfilename(L, arg), write, buf, sizeof buf, &err);
    if (!p) luaL_error(L, "%s", err);
    lua_pushstring(L, p);
    lua_replace(L, arg);
}

/* call the original function (upvalue 1) with the (checked) arguments */
static int call_original(lua_State *L) {
    int n = lua_gettop(L);
    lua_pushvalue(L, lua_upvalueindex(1));
    lua_insert(L, 1);
    lua_call(L, n, LUA_MULTRET);
    return lua_gettop(L);
}

/* the io library's own test of a mode: [rwa]+?b* */
static int valid_mode(const char *mode) {
    return *mode != '\0' && strchr("rwa", *(mode++)) != NULL && (*mode != '+' || ((void)(++mode), 1)) &&
           strspn(mode, "b") == strlen(mode);
}

static int stream_close(lua_State *L) {
    luaL_Stream *p = (luaL_Stream *)luaL_checkudata(L, 1, LUA_FILEHANDLE);
    return luaL_fileresult(L, fclose(p->f) == 0, NULL);
}

/* a file of the io library, opened for writing at path (resolved) without following a
 * link at its name: pushed, or nil, "given: reason", errno as io.open returns them */
static int open_for_writing(lua_State *L, const char *path, const char *given, const char *mode) {
    int flags = mode[1] == '+' ? O_RDWR : mode[0] == 'r' ? O_RDONLY : O_WRONLY;
    if (mode[0] == 'w') flags |= O_CREAT | O_TRUNC;
    if (mode[0] == 'a') flags |= O_CREAT | O_APPEND;
    if (!sb_from(L)->unsafe) flags |= O_NOFOLLOW;
    luaL_Stream *p = (luaL_Stream *)lua_newuserdatauv(L, sizeof *p, 0);
    p->closef = NULL;  /* not a file until it is open */
    luaL_setmetatable(L, LUA_FILEHANDLE);
    int fd = open(path, flags | O_CLOEXEC, 0666);
    if (fd >= 0 && !(p->f = fdopen(fd, mode))) {
        int e = errno;
        close(fd);
        errno = e;
        fd = -1;
    }
    if (fd < 0) {
        int e = errno;
        lua_pop(L, 1);
        luaL_pushfail(L);
        if (e == ELOOP) lua_pushfstring(L, "%s: a symbolic link (the sandbox does not write through one)", given);
        else lua_pushfstring(L, "%s: %s", given, strerror(e));
        lua_pushinteger(L, e);
        return 3;
    }
    p->closef = stream_close;
    return 1;
}

static int sb_io_open(lua_State *L) {
    const char *mode = luaL_optstring(L, 2, "r");
    if (!strpbrk(mode, "wa+")) {
        check_arg(L, 1, 0);
        return call_original(L);
    }
    const char *given = wbl_checkfilename(L, 1);
    luaL_argcheck(L, valid_mode(mode), 2, "invalid mode");
    char buf[PATH_MAX];
    const char *err, *p = wb_sandbox_path(L, given, 1, buf, sizeof buf, &err);
    if (!p) return luaL_error(L, "%s", err);
    return open_for_writing(L, p, given, mode);
}

static int sb_io_lines(lua_State *L) {  /* io.lines(): the default input; else a file name, read */
    if (!lua_isnoneornil(L, 1)) check_arg(L, 1, 0);
    return call_original(L);
}

/* io.input / io.output: nothing (the current file), a file name, or an open file handle */
static int handle_or_name(lua_State *L, int write) {
    if (lua_isnoneornil(L, 1) || luaL_testudata(L, 1, LUA_FILEHANDLE)) return call_original(L);
    if (lua_type(L, 1) != LUA_TSTRING) luaL_typeerror(L, 1, "file name or file handle");
    if (!write) {
        check_arg(L, 1, 0);
        return call_original(L);
    }
    /* opened here, as io.open does, and handed over as a file handle */
    const char *given = wbl_checkfilename(L, 1);
    char buf[PATH_MAX];
    const char *err, *p = wb_sandbox_path(L, given, 1, buf, sizeof buf, &err);
    if (!p) return luaL_error(L, "%s", err);
    if (open_for_writing(L, p, given, "w") != 1) return luaL_error(L, "cannot open file %s", lua_tostring(L, -2));
    lua_replace(L, 1);
    return call_original(L);
}

static int sb_io_input(lua_State *L) { return handle_or_name(L, 0); }
static int sb_io_output(lua_State *L) { return handle_or_name(L, 1); }

/* os.remove and os.rename act on the names themselves: a link is removed or moved, not
 * what it leads to (2: the entry, its last name not followed) */
static int sb_os_remove(lua_State *L) {
    check_arg(L, 1, 2);
    return call_original(L);
}

static int sb_os_rename(lua_State *L) {
    check_arg(L, 1, 2);
    check_arg(L, 2, 2);
    return call_original(L);
}

static int sb_os_exit(lua_State *L) {
    return luaL_error(L, "os.exit is not available in the sandbox (return from the script or raise an error; "
                         "--unsafe allows it)");
}

/* load: text chunks only, whatever mode the script asks for */
static int sb_load(lua_State *L) {
    lua_settop(L, lua_gettop(L) < 4 ? 3 : 4);  /* keep "env given as nil" apart from "no env" */
    lua_pushliteral(L, "t");
    lua_replace(L, 3);
    return call_original(L);
}

/* load a text chunk from a file already checked; chunk name relative to the cwd */
typedef struct { FILE *f; int pending; char c; char buf[4096]; } file_reader;

static const char *read_file(lua_State *L, void *ud, size_t *size) {
    file_reader *r = ud;
    (void)L;
    if (r->pending) {  /* the newline that ended a skipped "#!" line keeps line numbers right */
        r->pending = 0;
        *size = 1;
        return &r->c;
    }
    *size = fread(r->buf, 1, sizeof r->buf, r->f);
    return *size ? r->buf : NULL;
}

/* mode: what the caller allows ("t", "b", "bt"; NULL: both), narrowed to text in the sandbox */
static int load_text(lua_State *L, const char *path, const char *mode) {
    wb_sandbox *sb = sb_from(L);
    file_reader r = { fopen(path, "r"), 0, '\n', "" };
    if (!r.f) {
        lua_pushfstring(L, "cannot open %s: %s", display(sb, path), strerror(errno));
        return LUA_ERRFILE;
    }
    int ch = getc(r.f);
    if (ch == '#') {
        while ((ch = getc(r.f)) != EOF && ch != '\n') {}
        r.pending = ch == '\n';
        ch = ch == EOF ? EOF : getc(r.f);
    }
    /* a precompiled chunk (after a "#!" line too, as lua's own loadfile reads it) is
     * bytecode, which the VM does not verify: refused in the sandbox, named here */
    if (ch == LUA_SIGNATURE[0]) {
        r.pending = 0;
        if (!sb->unsafe) {
            fclose(r.f);
            lua_pushfstring(L, "cannot load %s: it is a precompiled (binary) chunk, not allowed in the sandbox "
                               "(--unsafe allows it)", display(sb, path));
            return LUA_ERRSYNTAX;
        }
    }
    if (ch != EOF) ungetc(ch, r.f);
    lua_pushfstring(L, "@%s", display(sb, path));
    if (!mode) mode = "bt";
    int status = lua_load(L, read_file, &r, lua_tostring(L, -1), sb->unsafe || !strchr(mode, 't') ? mode : "t");
    lua_remove(L, -2);
    fclose(r.f);
    return status;
}

static int sb_loadfile(lua_State *L) {
    int env = !lua_isnone(L, 3);
    int status;
    if (lua_isnoneornil(L, 1)) {
        status = luaL_loadfilex(L, NULL, sb_from(L)->unsafe ? luaL_optstring(L, 2, NULL) : "t");  /* stdin */
    } else {
        check_arg(L, 1, 0);
        status = load_text(L, lua_tostring(L, 1), luaL_optstring(L, 2, NULL));
    }
    if (status != LUA_OK) {  /* nil, message */
        luaL_pushfail(L);
        lua_insert(L, -2);
        return 2;
    }
    if (env) {
        lua_pushvalue(L, 3);
        if (!lua_setupvalue(L, -2, 1)) lua_pop(L, 1);
    }
    return 1;
}

static int sb_dofile(lua_State *L) {
    lua_settop(L, 1);
    int status;
    if (lua_isnil(L, 1)) {
        status = luaL_loadfilex(L, NULL, sb_from(L)->unsafe ? NULL : "t");
    } else {
        check_arg(L, 1, 0);
        status = load_text(L, lua_tostring(L, 1), NULL);
    }
    if (status != LUA_OK) return lua_error(L);
    lua_call(L, 0, LUA_MULTRET);
    return lua_gettop(L) - 1;
}

/* The first file of the template list tpl for name (sep in name replaced by rep) that
 * exists and that a script may read: the library folder or a readable folder. 1 and c
 * filled; or 0 with "no file ..." pushed, the same for a refused file as for a missing
 * one, so the search cannot tell whether a file exists elsewhere. */
static int find_file(lua_State *L, const char *name, const char *tpl, const char *sep, const char *rep, char *c) {
    wb_sandbox *sb = sb_from(L);
    int top = lua_gettop(L);
    const char *mod = *sep && strstr(name, sep) ? luaL_gsub(L, name, sep, rep) : name;
    lua_pushliteral(L, "");  /* files tried */
    char t[PATH_MAX], full[PATH_MAX];
    for (const char *s = tpl; *s;) {
        const char *start = s, *e = strchr(s, ';');
        size_t len = e ? (size_t)(e - s) : strlen(s);
        s += len + (e != NULL);
        if (len == 0 || len >= PATH_MAX) continue;
        memcpy(t, start, len);
        t[len] = 0;
        const char *cand = luaL_gsub(L, t, "?", mod);
        if (join(full, sizeof full, sb->cwd, cand) == 0 && canon(full, c) == 0 && exists(c) &&
            (sb->unsafe || may_read(sb, c) || (sb->lib[0] && under(c, sb->lib)))) {
            lua_settop(L, top);
            return 1;
        }
        lua_pushfstring(L, "%s%sno file '%s'", lua_tostring(L, -2), *lua_tostring(L, -2) ? "\n\t" : "", cand);
        lua_replace(L, -3);
        lua_pop(L, 1);
    }
    lua_copy(L, -1, top + 1);  /* below it, maybe, the name with sep replaced */
    lua_settop(L, top + 1);
    return 0;
}

/* require's Lua searcher: package.path through find_file, and only text is loaded */
static int sb_searcher(lua_State *L) {
    wb_sandbox *sb = sb_from(L);
    const char *name = luaL_checkstring(L, 1);
    char c[PATH_MAX];
    lua_settop(L, 1);
    lua_getfield(L, lua_upvalueindex(1), "path");
    const char *tpl = lua_tostring(L, 2);
    if (!tpl) return luaL_error(L, "'package.path' must be a string");
    if (!find_file(L, name, tpl, ".", "/", c)) return 1;
    if (load_text(L, c, NULL) != LUA_OK)
        return luaL_error(L, "error loading module '%s' from file '%s':\n\t%s", name, display(sb, c),
                          lua_tostring(L, -1));
    lua_pushstring(L, display(sb, c));
    return 2;
}

/* package.searchpath by the same rules: else it would tell whether any file exists */
static int sb_searchpath(lua_State *L) {
    const char *name = luaL_checkstring(L, 1), *tpl = luaL_checkstring(L, 2);
    const char *sep = luaL_optstring(L, 3, "."), *rep = luaL_optstring(L, 4, "/");
    char c[PATH_MAX];
    if (find_file(L, name, tpl, sep, rep, c)) {
        lua_pushstring(L, display(sb_from(L), c));
        return 1;
    }
    luaL_pushfail(L);
    lua_insert(L, -2);
    return 2;
}

/* replace t[name] by a C closure over the original function */
static void wrap(lua_State *L, int t, const char *name, lua_CFunction f) {
    t = lua_absindex(L, t);
    lua_getfield(L, t, name);
    lua_pushcclosure(L, f, 1);
    lua_setfield(L, t, name);
}

/* a refused function raises a message naming it, rather than "attempt to call a nil
 * value", so the script's author learns why and what to do */
static int sb_refused(lua_State *L) {
    return luaL_error(L, "%s is not available in the sandbox (--unsafe allows it)",
                      lua_tostring(L, lua_upvalueindex(1)));
}

static void drop(lua_State *L, int t, const char *lib, const char *name) {
    t = lua_absindex(L, t);
    lua_pushfstring(L, "%s.%s", lib, name);
    lua_pushcclosure(L, sb_refused, 1);
    lua_setfield(L, t, name);
}

/* files named by a script go through wb_sandbox_path in both modes, so a scene writes to
 * the same place with and without --unsafe; only the refusals depend on the mode */
static void open_paths(lua_State *L) {
    lua_pushglobaltable(L);
    lua_pushcfunction(L, sb_loadfile);
    lua_setfield(L, -2, "loadfile");
    lua_pushcfunction(L, sb_dofile);
    lua_setfield(L, -2, "dofile");
    lua_getfield(L, -1, "io");
    wrap(L, -1, "open", sb_io_open);
    wrap(L, -1, "lines", sb_io_lines);
    wrap(L, -1, "input", sb_io_input);
    wrap(L, -1, "output", sb_io_output);
    lua_pop(L, 1);
    lua_getfield(L, -1, "os");
    wrap(L, -1, "remove", sb_os_remove);
    wrap(L, -1, "rename", sb_os_rename);
    lua_pop(L, 2);
}

static void open_libs(lua_State *L) {
    static const luaL_Reg libs[] = {
        { LUA_GNAME, luaopen_base },       { LUA_LOADLIBNAME, luaopen_package },
        { LUA_COLIBNAME, luaopen_coroutine }, { LUA_TABLIBNAME, luaopen_table },
        { LUA_IOLIBNAME, luaopen_io },     { LUA_OSLIBNAME, luaopen_os },
        { LUA_STRLIBNAME, luaopen_string }, { LUA_MATHLIBNAME, luaopen_math },
        { LUA_UTF8LIBNAME, luaopen_utf8 }, { NULL, NULL } };  /* no debug */
    for (const luaL_Reg *l = libs; l->name; l++) {
        luaL_requiref(L, l->name, l->func, 1);
        lua_pop(L, 1);
    }
    lua_pushglobaltable(L);
    wrap(L, -1, "load", sb_load);
    lua_getfield(L, -1, "io");
    drop(L, -1, "io", "popen");
    drop(L, -1, "io", "tmpfile");  /* a file outside the output folder */
    lua_pop(L, 1);
    lua_getfield(L, -1, "os");
    drop(L, -1, "os", "execute");
    drop(L, -1, "os", "tmpname");
    drop(L, -1, "os", "setlocale");  /* process-wide: would change how every number is printed and parsed */
    lua_pushcfunction(L, sb_os_exit);
    lua_setfield(L, -2, "exit");
    lua_pop(L, 1);
    lua_getfield(L, -1, "string");
    drop(L, -1, "string", "dump");
    lua_pop(L, 1);
    lua_getfield(L, -1, "package");
    drop(L, -1, "package", "loadlib");
    lua_pushcfunction(L, sb_searchpath);
    lua_setfield(L, -2, "searchpath");
    lua_pushliteral(L, "");
    lua_setfield(L, -2, "cpath");
    lua_createtable(L, 2, 0);  /* searchers: preload, then Lua files through the rules */
    lua_getfield(L, -2, "searchers");
    lua_rawgeti(L, -1, 1);
    lua_rawseti(L, -3, 1);
    lua_pop(L, 1);
    lua_pushvalue(L, -2);
    lua_pushcclosure(L, sb_searcher, 1);
    lua_rawseti(L, -2, 2);
    lua_setfield(L, -2, "searchers");
    lua_pop(L, 2);
}


void wb_sandbox_open(lua_State *L, wb_sandbox *sb) {
    lua_pushlightuserdata(L, sb);
    lua_rawsetp(L, LUA_REGISTRYINDEX, &sandbox_key);
    if (sb->unsafe) luaL_openlibs(L);
    else open_libs(L);
    open_paths(L);
}

int wb_sandbox_init(wb_sandbox *sb, const char *scene_dir, const char *out_dir, const char *lib_dir,
                    const char *project_root, int unsafe) {
    char full[PATH_MAX];
    memset(sb, 0, sizeof *sb);
    sb->unsafe = unsafe;
    snprintf(sb->out_shown, sizeof sb->out_shown, "%s", out_dir ? out_dir : "out");
    if (!getcwd(sb->cwd, sizeof sb->cwd) ||
        join(full, sizeof full, sb->cwd, scene_dir ? scene_dir : ".") || canon(full, sb->scene) ||
        join(full, sizeof full, sb->cwd, out_dir ? out_dir : "out") || canon(full, sb->out) ||
        (lib_dir && (join(full, sizeof full, sb->cwd, lib_dir) || canon(full, sb->lib))))
        return -1;
    /* readable: the scene's folder, the assets folders next to it, here and in the
     * project, the output folder */
    const char *rel[][2] = { { sb->scene, "." },     { sb->scene, "../assets" }, { sb->cwd, "assets" },
                             { project_root, "assets" }, { sb->lib[0] ? sb->lib : NULL, "../assets" },
                             { sb->out, "." } };
    for (size_t i = 0; i < sizeof rel / sizeof rel[0]; i++)
        if (rel[i][0] && join(full, sizeof full, rel[i][0], rel[i][1]) == 0 && canon(full, sb->roots[sb->nroots]) == 0)
            sb->nroots++;
    return 0;
}

const char *wbl_path(lua_State *L, const char *path, int write, char *buf, size_t n)
{
    const char *err = NULL;
    const char *p = wb_sandbox_path(L, path, write, buf, n, &err);
    if (!p) luaL_error(L, "%s", err ? err : "bad path");
    return p;
}

int wbl_allow(void *ud, const char *path, int write, char *err, size_t errn)
{
    char buf[PATH_MAX];
    const char *e = NULL;
    if (wb_sandbox_path((lua_State *)ud, path, write, buf, sizeof buf, &e)) return 1;
    snprintf(err, errn, "%s", e ? e : "refused");
    return 0;
}
