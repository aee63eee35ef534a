-- api_extreme.lua: extreme but finite input. What a call derives (positions, rest
-- lengths, masses per particle, 1/h^2, weld tolerances, normals, skin weights) is either
-- representable or refused with `bad argument` naming the option, and nothing changes.

-- the world's particle and constraint counts and hash, to compare before and after
local function snapshot(w) return { w:particle_count(), #w:distances(), w:hash() } end
local function unchanged(w, s)
  local now = snapshot(w)
  expect.eq(now[1], s[1], "particle count")
  expect.eq(now[2], s[2], "constraint count")
  expect.eq(now[3], s[3], "hash")
end

test("builders refuse extents that overflow", function()
  local w = wobble.world{}
  w:particle{ pos = {0, 0, 0} }
  local s = snapshot(w)
  expect.error(function() w:rope{ from = {-1e308, 0, 0}, to = {1e308, 0, 0} } end,
               "bad argument #1 to 'rope' %(from/to: ")
  -- finite positions, but a link's length squared overflows
  expect.error(function() w:rope{ from = {-1e200, 0, 0}, to = {1e200, 0, 0} } end,
               "bad argument #1 to 'rope' %(from/to: the body is too large")
  expect.error(function() w:cloth{ origin = {1e308, 0, 0}, size = {1e308, 1} } end,
               "bad argument #1 to 'cloth' %(origin/size: ")
  expect.error(function() w:lattice{ min = {-1e308, -1e308, -1e308}, max = {1e308, 1e308, 1e308} } end,
               "bad argument #1 to 'lattice' %(min/max: ")
  unchanged(w, s)
  -- scaled into range they build
  local b = w:rope{ from = {-1e100, 0, 0}, to = {1e100, 0, 0} }
  expect.eq(b.count, 11)
end)

test("builders refuse a mass whose share per particle underflows", function()
  local w = wobble.world{}
  local s = snapshot(w)
  expect.error(function() w:rope{ mass = 1e-320 } end, "bad argument #1 to 'rope' %(mass: ")
  expect.error(function() w:cloth{ mass = 1e-310 } end, "bad argument #1 to 'cloth' %(mass: ")
  expect.error(function() w:lattice{ mass = 1e-310 } end, "bad argument #1 to 'lattice' %(mass: ")
  unchanged(w, s)
  local b = w:rope{ mass = 1e308 }
  expect.truthy(w:mass(b.particles[1]) > 0 and w:mass(b.particles[1]) < math.huge)
end)

test("a distance whose rest would be infinite is refused", function()
  local w = wobble.world{}
  local a = w:particle{ pos = {-1e200, 0, 0} }
  local b = w:particle{ pos = {1e200, 0, 0} }
  local c = w:particle{ pos = {0, 1, 0} }
  local s = snapshot(w)
  expect.error(function() w:distance(a, b) end, "bad argument #2 to 'distance' %(particles 1 and 2 are too far apart")
  expect.error(function() w:distance(a, b, { rest = 1 }) end, "too far apart")
  expect.error(function() w:distance(b, c, { rest = 1e200 }) end, "bad argument #3 to 'distance' %(field 'rest': must be finite and below 1e154")
  unchanged(w, s)
  -- the world still steps: nothing froze it
  w:step()
  expect.eq(w:stats().warnings, 0)
end)

test("dt too short to step is refused, by wobble.world and the setters", function()
  expect.error(function() wobble.world{ dt = 1e-300 } end, "bad argument #1 to 'world' %(dt/substeps is too short")
  expect.error(function() wobble.world{ dt = 1e-153, substeps = 100 } end, "dt/substeps is too short")
  local w = wobble.world{}
  expect.error(function() w:set_dt(1e-300) end, "bad argument #1 to 'set_dt' %(dt/substeps is too short")
  expect.eq(w:dt(), 1 / 60)
  w:set_dt(1e-150)
  expect.error(function() w:set_substeps(10000) end, "bad argument #1 to 'set_substeps' %(dt/substeps")
  expect.eq(w:substeps(), 10)
  -- the shortest accepted step runs without undoing frames
  local p = w:particle{ pos = {0, 1, 0} }
  local q = w:particle{ pos = {0, 2, 0} }
  w:distance(p, q)
  w:run{ frames = 3 }
  expect.eq(w:stats().warnings, 0)
end)

test("a compliance whose compliance/h^2 overflows is infinitely soft, not NaN", function()
  local w = wobble.world{}
  local p = w:particle{ pos = {0, 1, 0} }
  local q = w:particle{ pos = {0, 2, 0} }
  local c = w:distance(p, q, { compliance = 1e308 })
  w:run{ frames = 10 }
  expect.eq(w:stats().warnings, 0)
  local _, y = w:position(p)
  expect.truthy(y < 0.9, "fell freely")
  expect.eq(c:force(), 0)
end)

test("from_mesh with neighbours on vertices tied at distance 0", function()
  -- 5e-324 apart: every squared distance underflows to 0 (a heap overflow before)
  local v = {}
  for i = 0, 39 do v[#v + 1] = {i * 4.9406564584124654e-324, 0, 0} end
  local m = wobble.mesh{ vertices = v, triangles = {} }
  local w = wobble.world{}
  local b = w:from_mesh(m, { neighbours = 8 })
  expect.eq(b.count, 40)
  expect.truthy(#w:distances() <= 40 * 8)
end)

test("from_mesh refuses a mesh whose extent overflows", function()
  local m = wobble.mesh{ vertices = {{-1e200, 0, 0}, {1e200, 0, 0}, {0, 1e200, 0}}, triangles = {{1, 2, 3}} }
  local w = wobble.world{}
  local s = snapshot(w)
  expect.error(function() w:from_mesh(m) end, "bad argument #1 to 'from_mesh' %(the mesh is too large")
  unchanged(w, s)
end)

test("mesh weld and normals of huge and tiny meshes", function()
  -- the weld tolerance from a box whose diagonal overflows is finite
  local m = wobble.mesh{ vertices = {{-1e308, 0, 0}, {1e308, 0, 0}, {1e308, 1e308, 0}},
                         triangles = {{1, 2, 3}}, weld = true }
  expect.eq(m:vertex_count(), 3)
  expect.eq(m:triangle_count(), 1)
  for _, s in ipairs{ 1e-200, 1e200 } do
    local t = wobble.mesh{ vertices = {{0, 0, 0}, {s, 0, 0}, {0, s, 0}}, triangles = {{1, 2, 3}} }
    for i = 1, 3 do expect.eq(select(3, t:normal(i)), 1, "unit +z normal at scale " .. s) end
  end
end)

test("skin with neighbours tied at distance 0, and a vertex out of range", function()
  local w = wobble.world{}
  local ids, v = {}, {}
  for i = 0, 39 do
    local a = 2 * math.pi * i / 40
    ids[#ids + 1] = w:particle{ pos = {5e-163 * math.cos(a), 5e-163 * math.sin(a), 0} }
    v[#v + 1] = {1e-152 * math.cos(a), 1e-152 * math.sin(a), 0}
  end
  local sk = w:skin(wobble.mesh{ vertices = v, triangles = {} }, ids, { bones = 1, neighbours = 32 })
  expect.truthy(sk)
  local w2 = wobble.world{}
  local far = w2:particle{ pos = {-1e200, 0, 0} }
  expect.error(function() w2:skin(wobble.mesh{ vertices = {{1e200, 0, 0}}, triangles = {} }, {far}) end,
               "bad argument #2 to 'skin' %(mesh vertex 1 is too far")
end)

test("colliders: a capsule at 1e308, ends too far apart, a snapshot of such ends", function()
  local w = wobble.world{}
  -- the centre (a + b)/2 overflowed to inf
  local c = w:collider{ shape = "capsule", a = {1e308, 0, 0}, b = {1e308, 1, 0}, radius = 0.5 }
  expect.eq(c:position(), 1e308)
  expect.error(function() w:collider{ shape = "capsule", a = {-1e200, 0, 0}, b = {1e200, 0, 0}, radius = 1 } end,
               "a and b are too far apart")
  expect.error(function() w:collider{ shape = "plane", normal = {0, 1e-10, 0}, offset = 1e308 } end,
               "offset / |normal| overflows")
  -- a saved capsule's own-frame ends edited out of range are refused on load
  local v = wobble.world{}
  v:collider{ shape = "capsule", a = {0, 0, 0}, b = {1, 0, 0}, radius = 0.5 }
  v:save("api_extreme/capsule.json")
  local f = assert(io.open("api_extreme/capsule.json", "rb"))
  local s = f:read("a")
  f:close()
  local edited = s:gsub('"a": %[%-0%.5, 0, 0%]', '"a": [-1e200, 0, 0]'):gsub('"b": %[0%.5, 0, 0%]', '"b": [1e200, 0, 0]')
  expect.truthy(edited ~= s, "the snapshot was edited")
  f = assert(io.open("api_extreme/capsule_far.json", "wb"))
  f:write(edited)
  f:close()
  local loaded, err = wobble.load("api_extreme/capsule_far.json")
  expect.eq(loaded, nil)
  expect.truthy(err:find("too far apart", 1, true), err)
end)

test("JSON particle configs follow the same rules as w:distance", function()
  local function config(name, constraint)
    local f = assert(io.open("api_extreme/" .. name, "wb"))
    f:write('{"format": "wobble-particles", "version": 1,\n',
            ' "particles": [{"position": [-1e200, 0, 0]}, {"position": [1e200, 0, 0]}, {"position": [0, 1, 0]}, {"position": [1, 1, 0]}],\n',
            ' "constraints": [' .. constraint .. ']}\n')
    f:close()
    return "api_extreme/" .. name
  end
  local w = wobble.world{}
  local s = snapshot(w)
  local body, err = w:load_particles(config("far.json", '{"type": "distance", "particles": [0, 1], "rest": 1}'))
  expect.eq(body, nil)
  expect.truthy(err:find("constraints[0].particles: the particles are too far apart", 1, true), err)
  body, err = w:load_particles(config("rest.json", '{"type": "distance", "particles": [2, 3], "rest": 1e200}'))
  expect.eq(body, nil)
  expect.truthy(err:find("constraints[0].rest: must be finite and below 1e154 (its square overflows)", 1, true), err)
  unchanged(w, s)
end)
