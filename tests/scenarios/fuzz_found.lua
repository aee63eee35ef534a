-- fuzz_found.lua: inputs the fuzz targets (tests/fuzz, `make fuzz`) found mishandled, as
-- users meet them through the Lua API. The raw inputs are replayed by tests/fuzz/replay.sh
-- (tests/fuzz/regress); these check what a script sees.

local function write(name, text)
  local f = assert(io.open(name, "wb"))
  f:write(text)
  f:close()
  return name
end

test("a surface with no triangles loads (it read as 'out of memory')", function()
  local name = write("fuzz_found/empty_surface.json",
    '{"format": "wobble-particles", "version": 1, "particles": [{"position": [0, 0, 0]}],\n' ..
    ' "surfaces": [{"triangles": []}]}\n')
  local w = assert(wobble.load(name))
  expect.eq(w:particle_count(), 1)
  local u = wobble.world{}
  local b = assert(u:load_particles(name))
  expect.eq(b.count, 1)
  -- and it survives a save and a load
  expect.eq(w:save("fuzz_found/again.json"), true)
  expect.eq(assert(wobble.load("fuzz_found/again.json")):hash(), w:hash())
end)

-- a mesh of huge coordinates had an infinite weld tolerance (the diagonal squared
-- overflows), so weld = true and w:from_mesh refused it; normals were NaN past ~1e150
-- (overflowing cross products) and zero below ~1e-150 (underflowing ones)
test("a mesh of huge or tiny coordinates welds, keeps unit normals and makes a body", function()
  for _, s in ipairs{ 1e300, 1e-300 } do
    local V = { {-s, -s, -s}, {s, -s, -s}, {s, s, -s}, {-s, s, -s}, {0, 0, s}, {s, s, -s} }
    local T = { {1, 3, 2}, {1, 4, 3}, {1, 2, 5}, {2, 6, 5}, {3, 4, 5}, {4, 1, 5} }
    local m = wobble.mesh{ vertices = V, triangles = T, weld = true }
    expect.eq(m:vertex_count(), 5, s)   -- the repeated corner merged
    for i = 1, 5 do
      local x, y, z = m:normal(i)
      expect.near(math.sqrt(x * x + y * y + z * z), 1, 1e-12, s .. " normal " .. i)
    end
    -- clustering measures the extent too (a diagonal whose square overflowed was infinite,
    -- one whose square underflowed 0: one cluster): a strip of 12 vertices clusters to 3
    -- particles, as it does at scale 1
    local V, T = {}, {}
    for i = 0, 5 do V[#V + 1] = {i * s, 0, 0}; V[#V + 1] = {i * s, s, 0} end
    for i = 0, 4 do T[#T + 1] = {2 * i + 1, 2 * i + 3, 2 * i + 2}; T[#T + 1] = {2 * i + 2, 2 * i + 3, 2 * i + 4} end
    local strip = wobble.mesh{ vertices = V, triangles = T }
    local w = wobble.world{}
    if s < 1 then
      local b = w:from_mesh(m)
      expect.eq(b.count, 5, s)
      expect.eq(w:stats().distances, 9, s)
      expect.eq(wobble.world{}:from_mesh(strip, { target = 3 }).count, 3, s)
    else
      -- links of 1e300 m have no finite squared length: refused, naming why, nothing added
      expect.error(function() w:from_mesh(m) end, "too large")
      expect.error(function() w:from_mesh(strip, { target = 3 }) end, "too large")
      expect.eq(w:particle_count(), 0)
    end
  end
end)

-- an inv_mass so small that the mass overflows made a world that w:save could not write
-- ("the state holds a non-finite number"), w:mass() infinite; a mass so small that its
-- inverse overflows read as "particle mass must be >= 0" with no position
test("a mass or inv_mass whose inverse overflows is refused with its key", function()
  local function bad(name, text, expected)
    local path = write("fuzz_found/" .. name, text)
    local w = wobble.world{}
    local b, err = w:load_particles(path)
    expect.eq(b, nil, name)
    expect.truthy(type(err) == "string" and err:find(path .. expected, 1, true), tostring(err))
    expect.eq(w:particle_count(), 0)
    local v, err2 = wobble.load(path)
    expect.eq(v, nil, name)
    expect.truthy(type(err2) == "string" and err2:find(path .. expected, 1, true), tostring(err2))
  end
  local head = '{"format": "wobble-particles", "version": 1,\n'
  bad("inv_mass.json", head .. ' "particles": [{"position": [0, 0, 0], "inv_mass": 41e-320}]}',
      ":2:52: particles[0].inv_mass: 4.1e-319 is too small (its inverse, the mass, overflows)")
  bad("mass.json", head .. ' "particles": [{"position": [0, 0, 0], "mass": 1e-320}]}',
      ":2:48: particles[0].mass: ")
  bad("default_mass.json", head .. ' "defaults": {"mass": 1e-320}, "particles": []}',
      ":2:23: defaults.mass: ")
  -- the smallest inverse that still has a finite mass loads, and saves
  local w = assert(wobble.load(write("fuzz_found/inv_mass_ok.json",
    head .. ' "particles": [{"position": [0, 0, 0], "inv_mass": 1e-300}]}')))
  expect.eq(w:save("fuzz_found/inv_mass_ok_again.json"), true)
end)
