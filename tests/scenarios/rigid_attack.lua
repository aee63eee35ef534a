-- rigid_attack.lua: what a careless or hostile user did to rigid bodies and
-- what must happen: an error naming the place, and nothing changed.

local function write(name, text)
  local f = assert(io.open(name, "w"))
  f:write(text)
  f:close()
  return name
end

test("apply_impulse that would overflow the velocity is refused and changes nothing", function()
  local w = wobble.world{}
  local b = w:rigid{ shape = "box", vel = {1, 2, 3}, angular_velocity = {0.1, 0.2, 0.3} }
  local h = w:hash()
  -- finite J and point, but r x J overflows: the body's spin would be nan
  expect.error(function() b:apply_impulse({1e308, 0, 0}, {1e308, 1e308, 0}) end, "too large")
  expect.eq(w:hash(), h, "nothing changed")
  local light = w:rigid{ shape = "sphere", radius = 1, mass = 1e-3, pos = {5, 0, 0} }
  h = w:hash()
  expect.error(function() light:apply_impulse({1e308, 0, 0}) end, "too large") -- J / m
  expect.eq(w:hash(), h, "nothing changed")
  local x, y, z = b:angular_velocity()
  expect.eq(x, 0.1); expect.eq(y, 0.2); expect.eq(z, 0.3)
  -- the world still steps (a non-finite body would undo every frame)
  w:step(1 / 60)
  expect.near(select(2, b:position()), 2 / 60, 0.01, "moved")
  expect.eq(w:warnings(), 0)
end)

test("set_rotation refuses a quaternion w:rigid refuses (tiny, no direction)", function()
  local w = wobble.world{}
  local s = math.sqrt(0.5)
  local b = w:rigid{ shape = "box", rotation = {s, s, 0, 0} }
  expect.error(function() w:rigid{ shape = "box", rotation = {1e-200, 0, 0, 0} } end, "rotation")
  expect.error(function() b:set_rotation(1e-320, 0, 0, 0) end, "non-zero quaternion")
  expect.error(function() b:set_rotation(0, 1e-200, 0, 0) end, "non-zero quaternion")
  local qw, qx = b:rotation()
  expect.near(qw, s, 1e-15); expect.near(qx, s, 1e-15)
end)

-- a config of one box and one removed slot, as w:save writes them
local function config(first, second)
  return [[{ "format": "wobble-particles", "version": 1,
  "particles": [ {"position": [0, 2, 0]} ],
  "rigids": [ ]] .. first .. [[,
    ]] .. second .. [[ ] }]]
end
local box = [[{"shape": "box", "half": [0.5, 0.5, 0.5], "mass": 1, "pos": [0, 1, 0],
    "rotation": [1, 0, 0, 0], "generation": 1}]]

test("rigids entries as saved: errors name the entry and the key", function()
  local function bad(name, first, second, where, pattern)
    local path = write("rigid_attack/" .. name .. ".json", config(first, second))
    local ok, err = wobble.load(path)
    expect.falsy(ok, name)
    expect.truthy(err and err:find(path .. ":" .. where, 1, true), name .. ": " .. tostring(err) .. " at " .. where)
    expect.truthy(err and err:find(pattern, 1, true), name .. ": " .. tostring(err) .. " names " .. pattern)
  end
  -- the good one loads: a box and a dead slot
  local w = assert(wobble.load(write("rigid_attack/good.json", config(box, [[{"generation": 2}]]))))
  expect.eq(#w:rigids(), 1)
  -- an even generation is a removed slot: a shape there is a mistake, not to be ignored
  bad("even", box, [[{"generation": 2, "shape": "sphere", "radius": 1}]], "5:",
      "rigids[1].shape: a removed body's slot (even generation) has no other key")
  -- an entry with a generation is taken raw: its faults belong to it, not to line 1
  bad("unit", [[{"shape": "box", "rotation": [2, 0, 0, 0], "generation": 1}]], [[{"generation": 2}]], "3:",
      "rigids[0]: rigid body rotation must be a unit quaternion")
  bad("capsule", box, [[{"shape": "capsule", "a": [0, 0, 0], "b": [1, 0, 0], "radius": 0.1, "generation": 3}]], "5:",
      "rigids[1]: rigid capsule a and b must be about its centre")
end)

test("an attachment with neither collider nor rigid names both keys", function()
  local path = write("rigid_attack/notarget.json", [[{ "format": "wobble-particles", "version": 1,
  "particles": [ {"position": [0, 2, 0]} ],
  "rigids": [ {"shape": "sphere", "radius": 0.5} ],
  "attachments": [ {"particle": 0} ] }]])
  local ok, err = wobble.load(path)
  expect.falsy(ok)
  expect.truthy(err and err:find("attachments[0]: missing key 'collider' (or 'rigid')", 1, true), tostring(err))
end)
