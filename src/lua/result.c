/* result.c: what one run reports for `wobble collect`, so a sweep's runs can be gathered
 * into one table: the values a scene gives wobble.result{}, the frames stepped, and the
 * last world stepped (its hash and warnings, kept even when the script closes it), written
 * by the command line as OUTDIR/result.json. */
#include "util.h"
#include "io/io.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char values_key = 0;  /* registry: the table wobble.result{} merges into */
static const char record_key = 0;  /* registry: the run_record userdata */
static const char world_key = 0;   /* registry: the last world stepped (keeps it for the end) */

typedef struct run_record {
    int64_t frames;      /* frames stepped, every world together */
    int closed_known;    /* the last world was closed: its figures are below */
    uint64_t hash;
    int64_t warnings;
} run_record;

static run_record *record(lua_State *L, int create) {
    run_record *r = NULL;
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &record_key) == LUA_TUSERDATA) r = lua_touserdata(L, -1);
    lua_pop(L, 1);
    if (!r && create) {
        r = lua_newuserdatauv(L, sizeof *r, 0);
        memset(r, 0, sizeof *r);
        lua_rawsetp(L, LUA_REGISTRYINDEX, &record_key);
    }
    return r;
}

void wbl_result_after_frame(lua_State *L, int world_index) {
    world_index = lua_absindex(L, world_index);
    run_record *r = record(L, 1);
    r->frames++;
    r->closed_known = 0;
    lua_pushvalue(L, world_index);
    lua_rawsetp(L, LUA_REGISTRYINDEX, &world_key);
}

void wbl_result_world_closing(lua_State *L, const wbl_world *ud) {
    if (!ud->w) return;
    /* no allocation here: this runs from __gc too */
    int same = lua_rawgetp(L, LUA_REGISTRYINDEX, &world_key) == LUA_TUSERDATA && lua_touserdata(L, -1) == ud;
    lua_pop(L, 1);
    run_record *r = same ? record(L, 0) : NULL;
    if (!r) return;
    r->closed_known = 1;
    r->hash = wb_world_hash(ud->w);
    r->warnings = wb_world_warnings(ud->w);
}

/* wobble.result{ key = value, ... }: checked whole before anything is kept */
static int l_result(lua_State *L) {
    luaL_checktype(L, 1, LUA_TTABLE);
    lua_settop(L, 1);
    lua_pushnil(L);
    while (lua_next(L, 1)) {
        if (lua_type(L, -2) != LUA_TSTRING) {
            /* a number key shown as is; never a key's __tostring (it may fail or lie) */
            const char *tn = luaL_typename(L, -2), *ks = "";
            if (lua_type(L, -2) == LUA_TNUMBER) lua_pushvalue(L, -2), ks = lua_pushfstring(L, " %s", lua_tostring(L, -1));
            return luaL_argerror(L, 1, lua_pushfstring(L, "keys must be strings (names of results), got %s key%s",
                                                       tn, ks));
        }
        int t = lua_type(L, -1);
        if (t != LUA_TNUMBER && t != LUA_TSTRING && t != LUA_TBOOLEAN)
            /* the words of wbl_fielderror, which util.c (calling this file) holds */
            return luaL_argerror(L, 1, lua_pushfstring(L, "field '%s': expected a number, string or boolean, got %s",
                                                       lua_tostring(L, -2), luaL_typename(L, -1)));
        /* result.json holds C strings: a NUL byte would cut the key or value short */
        size_t kl, vl = 0;
        const char *k = lua_tolstring(L, -2, &kl);
        if (t == LUA_TSTRING) lua_tolstring(L, -1, &vl);
        if (strlen(k) != kl || (t == LUA_TSTRING && strlen(lua_tostring(L, -1)) != vl))
            return luaL_argerror(L, 1, lua_pushfstring(L, "field '%s': a %s holds a NUL byte (\\0)", k,
                                                       strlen(k) != kl ? "key" : "string"));
        lua_pop(L, 1);
    }
    if (lua_rawgetp(L, LUA_REGISTRYINDEX, &values_key) != LUA_TTABLE) {
        lua_pop(L, 1);
        lua_newtable(L);
        lua_pushvalue(L, -1);
        lua_rawsetp(L, LUA_REGISTRYINDEX, &values_key);
    }
    lua_pushnil(L);
    while (lua_next(L, 1)) {  /* a later call replaces a key an earlier one set */
        lua_pushvalue(L, -2);
        lua_insert(L, -2);
        lua_rawset(L, 2);
    }
    return 0;
}

void wbl_open_result(lua_State *L) {
    lua_pushcfunction(L, l_result);
    lua_setfield(L, -2, "result");
}

/* ---- result.json --------------------------------------------------------------------- */

/* what Lua would make of a --set value (main.c's prepare): true/false, a number, a string */
static cJSON *set_value(const char *v) {
    if (!strcmp(v, "true") || !strcmp(v, "false")) return cJSON_CreateBool(v[0] == 't');
    char *end;
    double d = strtod(v, &end);
    if (end != v && !*end && isfinite(d) && !strpbrk(v, "nNxX")) return cJSON_CreateNumber(d);
    return cJSON_CreateString(v);
}

void *wbl_result_take(lua_State *L) {
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    /* only raw reads of the registry: nothing here allocates Lua memory or runs Lua,
     * so it works past a spent budget */
    run_record *r = L ? record(L, 0) : NULL;
    int has = 0;
    uint64_t hash = 0;
    int64_t warnings = 0;
    if (r && r->closed_known) {
        has = 1, hash = r->hash, warnings = r->warnings;
    } else if (L) {
        if (lua_rawgetp(L, LUA_REGISTRYINDEX, &world_key) == LUA_TUSERDATA) {
            const wbl_world *ud = lua_touserdata(L, -1);
            if (ud->w) has = 1, hash = wb_world_hash(ud->w), warnings = wb_world_warnings(ud->w);
        }
        lua_pop(L, 1);
    }
    char hex[24];
    snprintf(hex, sizeof hex, "%016" PRIx64, hash);
    cJSON_AddNumberToObject(o, "frames", r ? (double)r->frames : 0);
    cJSON_AddNumberToObject(o, "warnings", (double)warnings);
    if (has) cJSON_AddStringToObject(o, "hash", hex);
    else cJSON_AddNullToObject(o, "hash");
    cJSON *res = cJSON_AddObjectToObject(o, "result"), *bad = cJSON_AddArrayToObject(o, "non_finite");
    if (L && lua_rawgetp(L, LUA_REGISTRYINDEX, &values_key) == LUA_TTABLE && res && bad) {
        lua_pushnil(L);
        while (lua_next(L, -2)) {
            const char *k = lua_tostring(L, -2);  /* a string key: no conversion */
            if (lua_type(L, -1) == LUA_TBOOLEAN) {
                cJSON_AddBoolToObject(res, k, lua_toboolean(L, -1));
            } else if (lua_type(L, -1) == LUA_TSTRING) {
                cJSON_AddStringToObject(res, k, lua_tostring(L, -1));
            } else {
                double v = lua_tonumber(L, -1);
                /* JSON has no NaN: the value as text, and its key in non_finite */
                if (isfinite(v)) {
                    cJSON_AddNumberToObject(res, k, v);
                } else {
                    cJSON_AddStringToObject(res, k, v != v ? "nan" : v > 0 ? "inf" : "-inf");
                    cJSON_AddItemToArray(bad, cJSON_CreateString(k));
                }
            }
            lua_pop(L, 1);
        }
    }
    if (L) lua_pop(L, 1);
    return o;
}

static const char *status_name(int code) {
    return code < 0 ? "running" : code == 0 ? "ok" : code == 1 ? "failed" : code == 2 ? "error" : "budget";
}

int wbl_result_write(void *taken, const wbl_run_info *info, char *err, size_t n) {
    cJSON *o = cJSON_CreateObject(), *sets = NULL, *figures = taken;
    char path[4096];
    int ok = 0;
    if (n) err[0] = 0;
    if (!o) goto done;
    cJSON_AddStringToObject(o, "format", "wobble-result");
    cJSON_AddNumberToObject(o, "version", 1);
    cJSON_AddStringToObject(o, "scene", info->scene);
    if ((sets = cJSON_AddObjectToObject(o, "set")))
        for (int i = 0; i < info->nsets; i++) {
            const char *kv = info->sets[i], *e = strchr(kv, '=');
            char *key = strndup(kv, (size_t)(e - kv));  /* any length: a fixed buffer cut long keys */
            if (!key) continue;
            cJSON_DeleteItemFromObjectCaseSensitive(sets, key);  /* the later --set wins, as in wobble.args */
            cJSON_AddItemToObject(sets, key, set_value(e + 1));
            free(key);
        }
    cJSON_AddStringToObject(o, "status", status_name(info->exit_code));
    if (info->exit_code >= 0) cJSON_AddNumberToObject(o, "exit", info->exit_code);
    else cJSON_AddNullToObject(o, "exit");
    cJSON_AddNumberToObject(o, "wall_time", info->wall_time);
    if (info->error) cJSON_AddStringToObject(o, "error", info->error);
    else cJSON_AddNullToObject(o, "error");
    while (figures && figures->child) {  /* frames, warnings, hash, result, non_finite */
        cJSON *it = cJSON_DetachItemViaPointer(figures, figures->child);
        char key[64];
        snprintf(key, sizeof key, "%s", it->string);
        cJSON_AddItemToObject(o, key, it);
    }
    char *text = cJSON_Print(o);
    if (!text) goto done;
    /* written aside and renamed: a reader never sees half a file */
    snprintf(path, sizeof path, "%s/result.json", info->out_dir);
    wbio_out f;
    char e[sizeof path + 128];
    if (wbio_out_open(&f, AT_FDCWD, path, path, e, sizeof e) == 0) {
        if (fputs(text, f.f) < 0 || fputc('\n', f.f) == EOF) f.failed = errno ? errno : EIO;
        ok = wbio_out_commit(&f, path, e, sizeof e) == 0;
    }
    if (!ok) snprintf(err, n, "cannot write %s", e);
    free(text);
done:
    if (!o) snprintf(err, n, "out of memory writing result.json");
    else if (!ok && !*err) snprintf(err, n, "out of memory writing result.json");
    cJSON_Delete(o);
    cJSON_Delete(figures);
    return ok;
}
