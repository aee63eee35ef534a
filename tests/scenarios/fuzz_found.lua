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
