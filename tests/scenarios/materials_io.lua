-- materials_io.lua: shape-matching clusters and pressures in snapshots and particle
-- configs ("shape_matches" and "pressures" sections), and the binding's argument checks.

local function write(name, text)
  local f = assert(io.open(name, "w"))
  f:write(text)
  f:close()
  return name
end

-- a plastic jelly block and a pressured lattice falling onto a floor, with a loose
-- particle in the cluster (ids not in one range) and a pinned one
local function scene(threads)
  local w = wobble.world{ threads = threads or 1, substeps = 8, iterations = 2 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  local loose = w:particle{ pos = {0.1, 1.9, 0}, mass = 0.3 }
  local jelly = w:lattice{ min = {-0.3, 1, -0.3}, max = {0.3, 1.6, 0.3}, res = {4, 4, 4}, mass = 2, compliance = 1e-2 }
  local ids = { loose }
  for _, p in ipairs(jelly.particles) do ids[#ids + 1] = p end
  local s = w:shape_match(ids, { stiffness = 0.4, yield = 0.01, creep = 8 })
  local bag = w:lattice{ min = {1, 0.5, -0.3}, max = {1.6, 1.1, 0.3}, res = {3, 3, 3}, mass = 1, compliance = 1e-3 }
  local p = w:pressure(bag, { pressure = 1.3, compliance = 1e-7 })
  w:pin(bag.first + 26)
  return w, s, p
end

test("a snapshot restores clusters and pressures exactly: same hash, same future", function()
  local w, s = scene()
  w:run{ frames = 45 }
  expect.gt(s:strain(), 0, "the cluster is deformed")
  w:save("materials_io/snap.json")
  local c = wobble.load("materials_io/snap.json")
  expect.eq(c:hash(), w:hash())
  for _ = 1, 30 do
    w:step()
    c:step()
  end
  expect.eq(c:hash(), w:hash(), "identical futures")
  -- the plastic rest shape and the rotations are state: a second save is the same text
  w:save("materials_io/a.json")
  c:save("materials_io/b.json")
  local fa, fb = io.open("materials_io/a.json"), io.open("materials_io/b.json")
  expect.eq(fa:read("a"), fb:read("a"))
  fa:close()
  fb:close()
end)

test("the hash covers the materials' state", function()
  local w1, s1 = scene()
  local w2 = scene()
  expect.eq(w1:hash(), w2:hash())
  w1:run{ frames = 40 }
  w2:run{ frames = 40 }
  expect.eq(w1:hash(), w2:hash())
  -- same particles, but a pressure changed: another hash
  local _, _, p3 = scene()
  local w3 = p3:world()
  p3:set_pressure(1.31)
  expect.truthy(w3:hash() ~= scene():hash())
  expect.truthy(s1:rest(2) ~= nil)
end)

test("deterministic for any thread count", function()
  local h = {}
  for _, t in ipairs{ 1, 2, 3 } do
    local w = scene(t)
    w:run{ frames = 40 }
    h[#h + 1] = w:hash()
  end
  expect.eq(h[2], h[1])
  expect.eq(h[3], h[1])
end)

local CONFIG = [[
{
  "format": "wobble-particles", "version": 1,
  "particles": [
    {"position": [0, 1, 0]}, {"position": [1, 1, 0]}, {"position": [0, 2, 0]}, {"position": [0, 1, 1], "mass": 3}
  ],
  "surfaces": [ {"triangles": [0, 2, 1,  0, 1, 3,  0, 3, 2,  1, 2, 3]} ],
  "shape_matches": [ {"particles": [0, 1, 2, 3], "stiffness": 0.5, "yield": 0.1} ],
  "pressures": [ {"surface": 0, "pressure": 1.5} ]
}
]]

test("a particle config's clusters and pressures are appended with the particles", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  w:particle{ pos = {5, 5, 5} } -- already there: ids and surfaces shift
  w:lattice{ min = {4, 4, 4}, max = {5, 5, 5}, res = {2, 2, 2} }
  local b = assert(w:load_particles(write("materials_io/tet.json", CONFIG)))
  expect.eq(b.first, 10)
  -- the pressure (1.5 x the tetrahedron's 1/6) pushes it out against the cluster
  -- (stiffness 0.5) pulling it back to its rest shape: it ends larger than at rest
  local function volume()
    local p = {}
    for i = 0, 3 do p[i] = { w:position(b.first + i) } end
    local function d(i) return { p[i][1] - p[0][1], p[i][2] - p[0][2], p[i][3] - p[0][3] } end
    local u, v, t = d(1), d(2), d(3)
    return math.abs(u[1] * (v[2] * t[3] - v[3] * t[2]) + u[2] * (v[3] * t[1] - v[1] * t[3]) +
                    u[3] * (v[1] * t[2] - v[2] * t[1])) / 6
  end
  expect.rel(volume(), 1 / 6, 1e-12)
  w:run{ frames = 30 }
  expect.gt(volume(), 1.05 / 6)
  -- through a snapshot: the same world
  w:save("materials_io/appended.json")
  local c = wobble.load("materials_io/appended.json")
  expect.eq(c:hash(), w:hash())
  -- a plain config without rest_volume takes the volume at load; yield without creep
  -- flows at 1/s (as w:shape_match); ids and surface indices follow the world's
  local f = io.open("materials_io/appended.json")
  local text = f:read("a")
  f:close()
  expect.truthy(text:find('"rest_volume": 0.1666666666666', 1, true))
  expect.truthy(text:find('"creep": 1,', 1, true))
  expect.truthy(text:find('"particles": [9, 10, 11, 12]', 1, true), "ids shifted after the world's")
  expect.truthy(text:find('"surface": 1,', 1, true), "the surface index shifted after the lattice's")
end)

test("bad clusters and pressures in a config are refused with their key path", function()
  local w = wobble.world{}
  local function bad(section, pattern)
    local text = CONFIG:gsub('"shape_matches".-\n.-\n', section .. "\n")
    local b, err = w:load_particles(write("materials_io/bad.json", text))
    expect.eq(b, nil)
    expect.truthy(err:find(pattern), string.format("%q does not match %q", err, pattern))
  end
  bad('"shape_matches": [ {"particles": [0, 1, 2, 3], "stiffness": 2} ], "pressures": []',
      "shape_matches%[0%]%.stiffness: must be in %[0, 1%]")
  bad('"shape_matches": [ {"particles": [0, 0, 2]} ], "pressures": []', "lists a particle twice")
  bad('"shape_matches": [ {"particles": [0, 7]} ], "pressures": []', "shape_matches%[0%]%.particles%[1%]")
  bad('"shape_matches": [ {"particles": [0]} ], "pressures": []', "at least 2 particles")
  bad('"shape_matches": [ {"particles": [0, 1], "rest": [0, 0, 0]} ], "pressures": []', "6 numbers expected")
  bad('"shape_matches": [ {"particles": [0, 1], "spin": 1} ], "pressures": []', "spin")
  bad('"shape_matches": [], "pressures": [ {"surface": 3} ]', "pressures%[0%]%.surface")
  bad('"shape_matches": [], "pressures": [ {"surface": 0, "pressure": -1} ]', "pressures%[0%]%.pressure: must be > 0")
  bad('"shape_matches": [], "pressures": [ {"surface": 0, "rest_volume": 0} ]', "rest_volume: must be > 0")
  expect.eq(w:particle_count(), 0, "nothing was added")
end)

test("w:shape_match checks its arguments and changes nothing when it refuses", function()
  local w = wobble.world{}
  local a = w:particle{ pos = {0, 0, 0} }
  local b = w:particle{ pos = {1, 0, 0} }
  local fixed = w:particle{ pos = {2, 0, 0}, mass = 0 }
  local fixed2 = w:particle{ pos = {3, 0, 0}, mass = 0 }
  local h = w:hash()
  expect.error(function() w:shape_match({ a, a }) end, "bad argument #1 to 'shape_match' %(a cluster lists a particle twice%)")
  expect.error(function() w:shape_match({ a }) end, "at least 2 particles")
  expect.error(function() w:shape_match({ fixed, fixed2 }) end, "a particle with mass")
  expect.error(function() w:shape_match({ a, 99 }) end, "bad argument #1 to 'shape_match'")
  expect.error(function() w:shape_match({ a, b }, { stiffness = 1.5 }) end, "stiffness.*must be in %[0, 1%]")
  expect.error(function() w:shape_match({ a, b }, { yield = -1 }) end, "yield.*must be >= 0")
  expect.error(function() w:shape_match({ a, b }, { rigid = true }) end, "rigid")
  expect.eq(w:hash(), h)
  local s = w:shape_match({ a, b, fixed }, {})
  expect.eq(s:stiffness(), 1)
  expect.eq(s:particles(), { a, b, fixed })
  expect.eq(s:world(), w)
  expect.eq({ s:rest(1) }, { -0.5, 0, 0 }, "about the mass centre (the immovable particle weighs nothing)")
  expect.error(function() s:rest(4) end, "out of range")
  expect.truthy(tostring(s):find("3 particles"))
  w:close()
  expect.error(function() s:strain() end, "stale")
end)
