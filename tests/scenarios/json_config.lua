-- json_config.lua: w:load_particles(path), the JSON particle config (schema version 1):
-- particles, distance constraints with defaults, colliders in the world form, surfaces,
-- named parts and skins, appended to a world that already holds things.

local function write(name, text)
  local f = assert(io.open(name, "w"))
  f:write(text)
  f:close()
  return name
end

local CONFIG = [[
{
  "format": "wobble-particles",
  "version": 1,
  "description": "two bars and a pinned hook",
  "defaults": {"mass": 0.5, "radius": 0.03, "compliance": 0.0001},
  "particles": [
    {"position": [0, 1, 0]},
    {"position": [1, 1, 0], "mass": 2},
    {"position": [2, 1, 0], "velocity": [0, 1, 0]},
    {"position": [0, 3, 0], "pinned": true},
    {"position": [1, 3, 0], "radius": 0.1},
    {"position": [0, 4, 0], "mass": 0}
  ],
  "constraints": [
    {"type": "distance", "particles": [0, 1]},
    {"type": "distance", "particles": [1, 2], "compliance": 0, "rest": 0.999},
    {"type": "distance", "particles": [3, 4], "damping": 0.1, "break_strain": 0.5, "yield": 0.01, "creep": 1}
  ],
  "colliders": [
    {"shape": "plane", "normal": [0, 2, 0], "offset": 0, "friction": 0.5},
    {"shape": "sphere", "center": [5, 0, 0], "radius": 0.5},
    {"shape": "box", "center": [0, -5, 0], "half": [1, 1, 1], "rotation": [1, 0, 0, 0], "restitution": 0.5},
    {"shape": "capsule", "a": [0, -9, 0], "b": [1, -9, 0], "radius": 0.2}
  ],
  "surfaces": [ {"triangles": [0, 1, 3, 1, 4, 3]} ],
  "parts": [ {"name": "bar", "first": 0, "count": 3}, {"name": "hook", "first": 3, "count": 2} ]
}
]]

test("a config adds particles, constraints, colliders and parts", function()
  local w = wobble.world{}
  w:particle{ pos = {9, 9, 9} } -- already there: the config's ids start after it
  w:collider{ shape = "plane", normal = {1, 0, 0}, offset = -10 }
  local b = assert(w:load_particles(write("json_config/two.json", CONFIG)))
  expect.eq(b.count, 6)
  expect.eq(b.first, 2)
  expect.eq(b.constraint_count, 3)
  expect.eq(w:particle_count(), 7)
  expect.eq(w:stats().distances, 3)
  expect.eq(w:stats().colliders, 5)
  expect.eq({ w:position(2) }, { 0, 1, 0 })
  expect.eq(w:mass(2), 0.5)                  -- defaults.mass
  expect.eq(w:mass(3), 2)
  expect.eq(w:radius(2), 0.03)               -- defaults.radius
  expect.eq(w:radius(6), 0.1)
  expect.eq({ w:velocity(4) }, { 0, 1, 0 })
  expect.eq(w:pinned(5), true)
  expect.eq(w:mass(7), 0)                    -- immovable
  -- parts: an array of bodies, also by name
  expect.eq(#b.parts, 2)
  expect.eq(b.parts.bar, b.parts[1])
  expect.eq(b.parts.bar.name, "bar")
  expect.eq(b.parts.hook.particles, { 5, 6 })
  expect.eq(b.parts.bar.first, 2)
  expect.eq(#b.skins, 0)
  -- body.colliders: handles of the four colliders the config made (not the plane before)
  expect.eq(#b.colliders, 4)
  expect.eq(b.colliders[1]:shape(), "plane")
  expect.eq(b.colliders[2]:shape(), "sphere")
  expect.eq({ b.colliders[2]:position() }, { 5, 0, 0 })
  expect.eq(b.colliders[4]:shape(), "capsule")
  expect.truthy(w:colliders()[2] == b.colliders[1])
  -- constraints: the given rest, else the current length; options as written
  local c = w:distance(2, 3) -- a fresh one beside: the config's are the three before
  expect.eq(c:rest(), 1)
  expect.near(w:max_strain(), 0.001 / 0.999, 1e-12, "the 0.999 rest of a 1 m link")
  b.colliders[2]:set_position(6, 0, 0)
  w:step()
  expect.eq({ b.colliders[2]:position() }, { 6, 0, 0 })
end)

test("the config behaves: the bar hangs under gravity, the hook is pinned", function()
  local w = wobble.world{ substeps = 20 }
  local b = assert(w:load_particles("json_config/two.json"))
  w:run{ seconds = 1 }
  expect.eq({ w:position(b.parts.hook.first) }, { 0, 3, 0 })
  local _, y = w:position(b.first)
  expect.near(y, 0.03, 0.01, "resting on the plane")
  expect.eq(w:warnings(), 0)
end)

test("loading twice appends a second copy", function()
  local w = wobble.world{}
  local a = assert(w:load_particles("json_config/two.json"))
  local b = assert(w:load_particles("json_config/two.json"))
  expect.eq(a.first, 1)
  expect.eq(b.first, 7)
  expect.eq(w:stats().distances, 6)
  expect.eq(w:stats().colliders, 8)
  expect.eq(b.parts.hook.first, 10)
  expect.eq(#a.colliders, 4)
  expect.eq(#b.colliders, 4)
  expect.falsy(a.colliders[1] == b.colliders[1])
  -- a removed collider's slot is reused by the next load: still the config's order
  a.colliders[2]:remove()
  local c = assert(w:load_particles("json_config/two.json"))
  expect.eq(#c.colliders, 4)
  expect.eq(c.colliders[1]:shape(), "plane")
  expect.eq(c.colliders[2]:shape(), "sphere")
  expect.eq(c.colliders[3]:shape(), "box")
end)

test("a minimal config: format, version and particles", function()
  local w = wobble.world{}
  local b = assert(w:load_particles(write("json_config/min.json",
    '{"format": "wobble-particles", "version": 1, "particles": []}')))
  expect.eq(b.count, 0)
  expect.eq(w:particle_count(), 0)
  -- a UTF-8 byte-order mark and CRLF line ends are fine
  b = assert(w:load_particles(write("json_config/bom.json",
    '\239\187\191{"format": "wobble-particles",\r\n "version": 1,\r\n "particles": [{"position": [1, 2, 3]}]}')))
  expect.eq({ w:position(b.first) }, { 1, 2, 3 })
  expect.eq(w:mass(b.first), 1)
  expect.eq(w:radius(b.first), 0.02)
end)

test("skins: a mesh bound to the config's particles", function()
  -- the mesh path is relative to the config's folder
  local m = wobble.mesh{ vertices = { {0.1, 0.1, 0}, {0.9, 0.1, 0}, {0.5, 0.9, 0} }, triangles = { {1, 2, 3} } }
  assert(m:save_obj("json_config/meshes/tri.obj"))
  local w = wobble.world{}
  local b = assert(w:load_particles(write("json_config/skinned.json", [[
{"format": "wobble-particles", "version": 1,
 "particles": [{"position": [0, 0, 0]}, {"position": [1, 0, 0]}, {"position": [0.5, 1, 0]}, {"position": [9, 9, 9]}],
 "constraints": [{"type": "distance", "particles": [0, 1]}, {"type": "distance", "particles": [1, 2]},
                 {"type": "distance", "particles": [2, 0]}],
 "skins": [{"mesh": "meshes/tri.obj", "bones": 2, "particles": [0, 1, 2]},
           {"mesh": "meshes/tri.obj", "scale": 2}]}]])))
  expect.eq(#b.skins, 2)
  expect.eq(b.skins[1]:bones(), { 1, 2, 3 })
  expect.eq(#b.skins[2]:bones(), 4)
  expect.eq(w:skins()[1], b.skins[1])
  local x, y = b.skins[1]:vertex(1)
  expect.near(x, 0.1, 1e-6)
  expect.near(y, 0.1, 1e-6)
  w:set_position(1, 0, 0, 5)
  w:set_position(2, 1, 0, 5)
  w:set_position(3, 0.5, 1, 5)
  expect.near(select(3, b.skins[1]:vertex(2)), 5, 1e-9)
  -- wobble.load of a config makes a world that has its skins
  local w2 = assert(wobble.load("json_config/skinned.json"))
  expect.eq(#w2:skins(), 2)
  expect.eq(w2:particle_count(), 4)
end)
