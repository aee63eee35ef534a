-- json_duplicates.lua: a key given twice in a particle config is an error wherever it
-- is (cJSON itself would keep both and let a lookup pick one): through w:load_particles
-- and through wobble.load of a snapshot, with nothing added. (json_errors.lua checks
-- the message's line and column; this file checks the other places and entry points.)

local function write(name, text)
  local f = assert(io.open(name, "w"))
  f:write(text)
  f:close()
  return name
end

local PARTICLES = '"particles": [{"position": [0, 0, 0]}, {"position": [1, 0, 0]}]'

test("a duplicate key in a collider, a constraint or the defaults is refused", function()
  for _, case in ipairs{
    { '"colliders": [{"shape": "sphere", "center": [0,0,0], "radius": 1, "radius": 2}]', "colliders[0].radius" },
    { '"constraints": [{"type": "distance", "particles": [0, 1], "compliance": 0, "compliance": 1}]',
      "constraints[0].compliance" },
    { '"defaults": {"mass": 1, "mass": 2}', "defaults.mass" },
  } do
    local w = wobble.world{}
    w:particle{ pos = {5, 5, 5} }
    local before = w:hash()
    local text = '{"format": "wobble-particles", "version": 1, ' .. PARTICLES .. ',\n ' .. case[1] .. '}'
    local b, err = w:load_particles(write("json_duplicates/c.json", text))
    expect.eq(b, nil, case[2])
    expect.truthy(type(err) == "string" and err:find(case[2] .. ": duplicate key", 1, true), tostring(err))
    expect.eq(w:hash(), before, "nothing added")
    -- the same file without the repetition loads
    local once = text:gsub(', "radius": 2', ""):gsub(', "compliance": 1', ""):gsub(', "mass": 2', "")
    expect.truthy(w:load_particles(write("json_duplicates/ok.json", once)), case[2] .. " once")
  end
end)

test("a snapshot with a repeated key does not load", function()
  local w = wobble.world{}
  w:particle{ pos = {0, 1, 0} }
  w:save("json_duplicates/snap.json")
  local f = assert(io.open("json_duplicates/snap.json"))
  local text = f:read("a")
  f:close()
  expect.truthy(wobble.load("json_duplicates/snap.json"), "the snapshot as written loads")
  -- repeat the "version" key at the top
  local twice = text:gsub('"version"%s*:%s*1', '"version": 1, "version": 1', 1)
  expect.truthy(twice ~= text, "the snapshot has a version key")
  local v, err = wobble.load(write("json_duplicates/snap2.json", twice))
  expect.eq(v, nil)
  expect.truthy(type(err) == "string" and err:find("duplicate key 'version'", 1, true), tostring(err))
end)
