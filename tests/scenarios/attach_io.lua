-- attach_io.lua: attachments and grabs in snapshots (exact round trip: same w:hash(),
-- identical futures), in particle configs (w:load_particles), in the determinism hash,
-- for any thread count; and the errors of w:attach / w:grab and of stale handles.

local function write(name, text)
  local f = assert(io.open(name, "w"))
  f:write(text)
  f:close()
  return name
end

-- a drum turning with a rope wound on, a box sliding with a particle riding it, a dead
-- collider slot before them, a removed attachment and a released grab (dead slots), a
-- compliant grab mid-move
local function scene(threads)
  local w = wobble.world{ substeps = 8, threads = threads or 1 }
  local gone = w:collider{ shape = "sphere", center = {9, 9, 9}, radius = 1 }
  local drum = w:collider{ shape = "capsule", a = {0, 0, -0.3}, b = {0, 0, 0.3}, radius = 0.2 }
  local box = w:collider{ shape = "box", center = {2, 0, 0}, half = {0.2, 0.2, 0.2}, rotation = {1, 0, 0.2, 0} }
  gone:remove()
  local rope = w:rope{ from = {0.22, 0, 0}, to = {0.22, -1.5, 0}, segments = 15, mass = 0.5 }
  local rider = w:particle{ pos = {2, 0.3, 0} }
  local spare = w:particle{ pos = {-1, 1, 0} }
  w:attach(spare, drum):remove()
  w:grab(spare, {0, 0, 0}):release()
  w:attach(rope.particles[1], drum)
  w:attach(rider, box, { compliance = 1e-4 })
  local g = w:grab(rope.particles[#rope.particles], {0.5, -1.4, 0}, { compliance = 1e-3 })
  drum:set_angular_velocity(0, 0, 2)
  box:set_velocity(0.3, 0, 0.1)
  box:set_angular_velocity(0, 1, 0)
  return w, g
end

test("save and load round-trip attachments and grabs exactly", function()
  local w, g = scene()
  w:run{ frames = 20 }
  g:move(0.7, -1.2, 0.1)  -- a move not yet stepped: the sweep must survive the trip
  expect.eq(w:save("attach_io/snap.json"), true)
  local v = assert(wobble.load("attach_io/snap.json"))
  expect.eq(v:hash(), w:hash())
  expect.eq(v:stats().attachments, 2)
  expect.eq(v:stats().grabs, 1)
  local _, pe1 = w:energy()
  local _, pe2 = v:energy()
  expect.eq(pe2, pe1, "the elastic energy of the compliant ones too")
  for _ = 1, 40 do w:step() v:step() end
  expect.eq(v:hash(), w:hash(), "identical futures")
  -- the loaded world's handles work
  local vg = v:grabs()[1]
  vg:move(0, -1, 0)
  g:move(0, -1, 0)
  w:step() v:step()
  expect.eq(v:hash(), w:hash())
  expect.eq(#v:attachments(), 2)
end)

test("the hash sees attachments and grabs", function()
  local w = wobble.world{}
  local c = w:collider{ shape = "sphere", center = {0, 0, 0}, radius = 0.1 }
  local p = w:particle{ pos = {0, 1, 0} }
  local h0 = w:hash()
  local a = w:attach(p, c)
  local h1 = w:hash()
  expect.truthy(h1 ~= h0, "attach changes the hash")
  a:remove()
  expect.eq(w:hash(), h0, "and removing it restores it")
  local g = w:grab(p, {0, 1, 0})
  expect.truthy(w:hash() ~= h0, "grab changes the hash")
  g:move(0, 2, 0)
  expect.truthy(w:hash() ~= h1, "moving it too")
end)

test("the same future for any thread count", function()
  local a, b = scene(1), scene(4)
  a:run{ frames = 30 }
  b:run{ frames = 30 }
  expect.eq(b:hash(), a:hash())
end)

test("a particle config's attachments and grabs (collider counted among the file's)", function()
  local name = write("attach_io/cfg.json", [[
{ "format": "wobble-particles", "version": 1,
  "particles": [ {"position": [0, 1, 0]}, {"position": [1, 1, 0]}, {"position": [2, 0, 0]} ],
  "colliders": [ {"shape": "sphere", "center": [5, 5, 5], "radius": 0.5},
                 {"shape": "box", "center": [0, 0.5, 0], "half": [0.1, 0.1, 0.1]} ],
  "attachments": [ {"particle": 0, "collider": 1} ],
  "grabs": [ {"particle": 2, "target": [2, 0.5, 0], "compliance": 0} ] }
]])
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = -5 }  -- slots shift on append
  local b = assert(w:load_particles(name))
  expect.eq(w:stats().attachments, 1)
  expect.eq(w:stats().grabs, 1)
  local box
  for _, c in ipairs(w:colliders()) do if c:shape() == "box" then box = c end end
  box:set_velocity(1, 0, 0)
  w:run{ frames = 60 }
  local x, y = w:position(b.first)
  expect.near(x, 1, 1e-12, "rides the config's box")
  expect.near(y, 1, 1e-12, "held at its point")
  local gx, gy = w:position(b.first + 2)
  expect.near(gx, 2, 1e-12, "grabbed")
  expect.near(gy, 0.5, 1e-12, "at its target")
end)

test("config errors name the key", function()
  local function bad(body, pattern)
    local name = write("attach_io/bad.json", [[{ "format": "wobble-particles", "version": 1,
      "particles": [ {"position": [0, 1, 0]} ], ]] .. body .. "}")
    local ok, err = wobble.load(name)
    expect.falsy(ok)
    expect.truthy(err and err:find(pattern, 1, true), "error " .. tostring(err) .. " names " .. pattern)
  end
  bad([["attachments": [ {"particle": 0, "collider": 0} ] ]], "attachments[0].collider: there are no colliders")
  bad([["colliders": [ {"shape": "sphere", "center": [0,0,0], "radius": 1} ],
        "attachments": [ {"particle": 3, "collider": 0} ] ]], "attachments[0].particle")
  bad([["colliders": [ {"shape": "sphere", "center": [0,0,0], "radius": 1} ],
        "attachments": [ {"particle": 0, "collider": 0, "compliance": -1} ] ]], "attachments[0].compliance")
  bad([["grabs": [ {"particle": 0} ] ]], "grabs[0]")
  bad([["grabs": [ {"particle": 0, "target": [0, 0]} ] ]], "grabs[0].target")
  bad([["grabs": [ {"particle": 0, "target": [0, 0, 0], "speed": 1} ] ]], "speed")
end)

test("w:attach and w:grab errors name the argument; nothing changes", function()
  local w = wobble.world{}
  local c = w:collider{ shape = "sphere", center = {0, 0, 0}, radius = 0.1 }
  local p = w:particle{ pos = {0, 1, 0} }
  local h = w:hash()
  expect.error(function() w:attach(p, "drum") end, "bad argument #2 to 'attach' %(collider or rigid body expected, got string%)")
  expect.error(function() w:attach(p, {}) end, "bad argument #2 to 'attach'")
  expect.error(function() w:attach(99, c) end, "bad argument #1 to 'attach'")
  expect.error(function() w:attach(p, c, { compliance = -1 }) end, "compliance")
  expect.error(function() w:attach(p, c, { stiffness = 1 }) end, "stiffness")
  local other = wobble.world{}
  local oc = other:collider{ shape = "sphere", center = {0, 0, 0}, radius = 0.1 }
  expect.error(function() w:attach(p, oc) end, "bad argument #2 to 'attach' %(the collider belongs to another world")
  local dead = w:collider{ shape = "sphere", center = {0, 0, 0}, radius = 0.1 }
  dead:remove()
  h = w:hash()
  expect.error(function() w:attach(p, dead) end, "bad argument #2 to 'attach' %(the collider was removed%)")
  expect.error(function() w:grab(p) end, "bad argument #2 to 'grab'")
  expect.error(function() w:grab(p, {0, 0 / 0, 0}) end, "bad argument #2 to 'grab'")
  expect.error(function() w:grab(p, {0, 0, 0}, { compliance = 1 / 0 }) end, "compliance")
  expect.eq(w:hash(), h, "nothing changed")
  expect.eq(w:stats().attachments + w:stats().grabs, 0)
  local g = w:grab(p, {0, 1, 0})
  expect.error(function() g:move(0, 1 / 0, 0) end, "bad argument #2 to 'move'")
  -- handles go stale with their world
  local a = w:attach(p, c)
  w:close()
  expect.falsy(a:valid())
  expect.falsy(g:valid())
  expect.error(function() g:move(0, 0, 0) end, "world was closed")
  expect.error(function() a:force() end, "world was closed")
  expect.truthy(tostring(g):find("released"), "tostring of a stale grab")
end)
