/* material.c: the material presets of the core (wb_material_preset) in Lua: the option
 * `material = "rubber"` every builder takes, and wobble.materials to read them. */
#include <string.h>

#include "util.h"

/* the preset named by field 'material' of the options at arg: NULL when absent; an
 * unknown name raises an error naming the key and the valid names */
const wb_material *wbl_opt_material(lua_State *L, int arg)
{
    if (lua_type(L, arg) != LUA_TTABLE) return NULL;
    const int t = lua_getfield(L, arg, "material");
    if (t == LUA_TNIL) {
        lua_pop(L, 1);
        return NULL;
    }
    const wb_material *m = t == LUA_TSTRING ? wb_material_preset(lua_tostring(L, -1)) : NULL;
    if (!m) {
        luaL_Buffer b;
        luaL_buffinit(L, &b);
        for (int32_t i = 0; i < wb_material_count(); i++) {
            if (i) luaL_addstring(&b, i + 1 < wb_material_count() ? ", " : " or ");
            luaL_addchar(&b, '"');
            luaL_addstring(&b, wb_material_at(i)->name);
            luaL_addchar(&b, '"');
        }
        luaL_pushresult(&b);
        const char *names = lua_tostring(L, -1);
        if (t == LUA_TSTRING)
            wbl_fielderror(L, arg, "material", "unknown material \"%s\" (one of %s)", lua_tostring(L, -2), names);
        wbl_fielderror(L, arg, "material", "a preset name expected, got %s (one of %s)", luaL_typename(L, -2), names);
    }
    lua_pop(L, 1);
    return m;
}

bool wbl_given(lua_State *L, int arg, const char *key)
{
    if (lua_type(L, arg) != LUA_TTABLE) return false;
    const bool g = lua_getfield(L, arg, key) != LUA_TNIL;
    lua_pop(L, 1);
    return g;
}

/* the preset's friction unless the options give one */
void wbl_material_friction(lua_State *L, int arg, const wb_material *m, wbl_contact_opts *co)
{
    if (m && !wbl_given(L, arg, "friction")) co->friction = m->friction;
}

static void setnum(lua_State *L, const char *k, wb_real v)
{
    lua_pushnumber(L, v);
    lua_setfield(L, -2, k);
}

/* wobble.materials: the presets in order (ipairs) and by name, each a table
 * { name, young, poisson, density, damping, friction, thickness } (a copy: editing it
 * changes nothing) */
void wbl_open_materials(lua_State *L)
{
    const int32_t n = wb_material_count();
    lua_createtable(L, n, n);
    for (int32_t i = 0; i < n; i++) {
        const wb_material *m = wb_material_at(i);
        lua_createtable(L, 0, 7);
        lua_pushstring(L, m->name);
        lua_setfield(L, -2, "name");
        setnum(L, "young", m->young);
        setnum(L, "poisson", m->poisson);
        setnum(L, "density", m->density);
        setnum(L, "damping", m->viscosity);
        setnum(L, "friction", m->friction);
        setnum(L, "thickness", m->thickness);
        lua_pushvalue(L, -1);
        lua_rawseti(L, -3, i + 1);
        lua_setfield(L, -2, m->name);
    }
    lua_setfield(L, -2, "materials");
}
