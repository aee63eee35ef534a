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
    local w = wobble.world{}
    local b = w:from_mesh(m)
    expect.eq(b.count, 5, s)
    expect.eq(w:stats().distances, 9, s)
    -- clustering measures the extent too (a diagonal whose square overflowed was infinite,
    -- one whose square underflowed 0: one cluster): a strip of 12 vertices clusters to 3
    -- particles, as it does at scale 1
    local V, T = {}, {}
    for i = 0, 5 do V[#V + 1] = {i * s, 0, 0}; V[#V + 1] = {i * s, s, 0} end
    for i = 0, 4 do T[#T + 1] = {2 * i + 1, 2 * i + 3, 2 * i + 2}; T[#T + 1] = {2 * i + 2, 2 * i + 3, 2 * i + 4} end
    local strip = wobble.mesh{ vertices = V, triangles = T }
    expect.eq(wobble.world{}:from_mesh(strip, { target = 3 }).count, 3, s)
  end
end)
