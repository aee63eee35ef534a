-- rigid_api.lua: the w:rigid handle: what it holds, what it refuses, impulses.
--
-- Mass properties: a box's principal moments are m (b^2 + c^2) / 3 (half extents), a
-- sphere's 2/5 m r^2, a capsule's a cylinder's plus two hemispheres' with the parallel
-- axis term of their centroids (3r/8 from the flat face). An impulse J at r from the
-- centre gives dv = J / m and dom = I^-1 (r x J), exactly (round-off, 1e-15).

test("w:rigid holds what it was given; getters and setters", function()
  local w = wobble.world{}
  local s = math.sqrt(0.5)
  local b = w:rigid{ shape = "box", half = {0.1, 0.2, 0.3}, mass = 2, pos = {1, 2, 3}, rotation = {2 * s, 0, 2 * s, 0},
                     vel = {4, 5, 6}, angular_velocity = {0.1, 0.2, 0.3}, friction = 0.4, restitution = 0.5 }
  local x, y, z = b:position(); expect.eq(x, 1); expect.eq(y, 2); expect.eq(z, 3)
  local qw, qx, qy, qz = b:rotation()
  expect.near(qw, s, 1e-15); expect.eq(qx, 0); expect.near(qy, s, 1e-15); expect.eq(qz, 0)
  expect.eq(select(3, b:velocity()), 6)
  expect.eq(select(2, b:angular_velocity()), 0.2)
  expect.eq(b:mass(), 2)
  expect.eq(b:shape(), "box")
  b:set_position(0, 1, 0); b:set_velocity(0, 0, 0); b:set_angular_velocity(0, 0, 0); b:set_rotation(2, 0, 0, 0)
  expect.eq(select(2, b:position()), 1)
  expect.eq(b:rotation(), 1)
  -- distance to the surface: 0.2 above the centre along y is on the top face
  expect.near(b:distance(0, 1.2, 0), 0, 1e-15)
  expect.near(b:distance(0, 1.5, 0), 0.3, 1e-15)
  -- a capsule's centre is the midpoint of a and b (given about pos)
  local c = w:rigid{ shape = "capsule", a = {0, 0, 0}, b = {2, 0, 0}, radius = 0.1, pos = {0, 5, 0} }
  x, y = c:position(); expect.eq(x, 1); expect.eq(y, 5)
  expect.near(c:distance(2.1, 5, 0), 0, 1e-15)
  expect.eq(#w:rigids(), 2)
  expect.truthy(w:rigids()[2] == c)
  c:remove()
  expect.falsy(c:valid())
  expect.error(function() c:position() end, "stale rigid body handle")
  expect.eq(#w:rigids(), 1)
  expect.truthy(b:valid())
  expect.eq(b:world(), w)
end)

test("w:rigid refuses bad options, naming the key, and adds nothing", function()
  local w = wobble.world{}
  local h = w:hash()
  expect.error(function() w:rigid{ shape = "box", radius = 1 } end, "radius")
  expect.error(function() w:rigid{ shape = "plane" } end, "shape")
  expect.error(function() w:rigid{ } end, "shape")
  expect.error(function() w:rigid{ shape = "box", mass = 0 } end, "mass must be > 0")
  expect.error(function() w:rigid{ shape = "sphere", radius = -1 } end, "radius must be > 0")
  expect.error(function() w:rigid{ shape = "box", half = {1, 0, 1} } end, "half extents")
  expect.error(function() w:rigid{ shape = "box", rotation = {0, 0, 0, 0} } end, "rotation must not be zero")
  expect.error(function() w:rigid{ shape = "box", restitution = 2 } end, "restitution")
  expect.error(function() w:rigid{ shape = "box", friction = -1 } end, "friction")
  expect.error(function() w:rigid{ shape = "box", pos = {0, 0} } end, "pos")
  expect.error(function() w:rigid{ shape = "box", bogus = 1 } end, "bogus")
  local ok, err = pcall(function() w:rigid{ shape = "box", mass = -1 } end)
  expect.falsy(ok)
  expect.truthy(tostring(err):find("rigid_api.lua:%d+:"), "names the script's line: " .. tostring(err))
  expect.eq(w:hash(), h, "nothing added")
  expect.eq(#w:rigids(), 0)
end)

test("an impulse at a point: dv = J/m, dom = I^-1 (r x J); its inertia tensors", function()
  local w = wobble.world{}
  local m, a, b, c = 3, 0.1, 0.2, 0.4
  local box = w:rigid{ shape = "box", half = {a, b, c}, mass = m }
  box:apply_impulse({0, 0, 6}, {0, 0.5, 0})    -- r x J = (3, 0, 0)
  local vx, vy, vz = box:velocity()
  expect.eq(vx, 0); expect.eq(vy, 0); expect.near(vz, 2, 1e-15)
  local ox, oy, oz = box:angular_velocity()
  expect.near(ox, 3 / (m * (b * b + c * c) / 3), 1e-12); expect.near(oy, 0, 1e-15); expect.near(oz, 0, 1e-15)
  box:apply_impulse({1, 0, 0}, { at = {0, 0, 0} })
  expect.near(box:velocity(), 1 / m, 1e-15)
  -- sphere: 2/5 m r^2
  local s = w:rigid{ shape = "sphere", radius = 0.5, mass = 2 }
  s:apply_impulse({0, 0, 1}, {0, 1, 0})
  expect.near(s:angular_velocity(), 1 / (0.4 * 2 * 0.25), 1e-12)
  -- capsule along x, length L, radius r: about y (transverse) the cylinder's
  -- mc (L^2/12 + r^2/4) and the caps' ms (2/5 r^2 + L^2/4 + 3 L r / 8); about x (axial)
  -- mc r^2/2 + ms 2/5 r^2; masses by volume
  local L, r, M = 1, 0.25, 4
  local vc, vs = math.pi * r * r * L, 4 / 3 * math.pi * r ^ 3
  local mc, ms = M * vc / (vc + vs), M * vs / (vc + vs)
  local it = mc * (L * L / 12 + r * r / 4) + ms * (0.4 * r * r + L * L / 4 + 3 * L * r / 8)
  local ia = mc * r * r / 2 + ms * 0.4 * r * r
  local cap = w:rigid{ shape = "capsule", a = {-L / 2, 0, 0}, b = {L / 2, 0, 0}, radius = r, mass = M }
  cap:apply_impulse({0, 0, 1}, {1, 0, 0})      -- r x J = (0, -1, 0): about y
  cap:apply_impulse({0, 1, 0}, {0, 0, 1})      -- (0,0,1) x (0,1,0) = (-1, 0, 0): about x
  ox, oy, oz = cap:angular_velocity()
  expect.near(oy, -1 / it, 1e-12, "transverse"); expect.near(ox, -1 / ia, 1e-12, "axial"); expect.near(oz, 0, 1e-15)
  -- the capsule's transverse moment against a direct sum over slices (midpoint rule)
  local sum, n = 0, 4000
  local rho = M / (vc + vs)
  for i = 1, n do
    local xx = -L / 2 - r + (L + 2 * r) * (i - 0.5) / n
    local e = math.max(math.abs(xx) - L / 2, 0)
    local rr = math.sqrt(math.max(r * r - e * e, 0))
    local dm = rho * math.pi * rr * rr * (L + 2 * r) / n
    sum = sum + dm * (xx * xx + rr * rr / 4)          -- a disc about a diameter, shifted
  end
  expect.rel(it, sum, 1e-5, "capsule transverse moment = the slices' sum")
end)

-- Snapshots: w:save writes every rigid body slot raw (pose, velocities, a removed
-- body's generation), so wobble.load gives the same hash and the same future, bit for
-- bit; and the hash sees a rigid body's state.
test("snapshots: a saved world with rigid bodies loads with the same hash and future", function()
  local w = wobble.world{ substeps = 5 }
  w:collider{ shape = "plane", friction = 0.4 }
  local a = w:rigid{ shape = "box", half = {0.2, 0.1, 0.3}, pos = {0, 1, 0}, rotation = {0.9, 0.1, 0.3, 0.2},
                     angular_velocity = {1, 2, 3}, friction = 0.3, restitution = 0.2, mass = 2 }
  local gone = w:rigid{ shape = "sphere", radius = 0.1, pos = {3, 1, 0} }
  w:rigid{ shape = "capsule", a = {-0.3, 0.5, 1}, b = {0.3, 0.9, 1.1}, radius = 0.1, vel = {1, 0, 0} }
  w:rigid{ shape = "sphere", radius = 0.2, pos = {1, 2, -1}, restitution = 0.5 }
  w:particle{ pos = {0, 3, 0} }
  for _ = 1, 20 do w:step() end
  gone:remove()
  local h0 = w:hash()
  a:set_velocity(0, 0, 0)
  expect.truthy(w:hash() ~= h0, "the hash sees a rigid body's velocity")
  a:set_velocity(0, 0, 0)
  w:save("rigid_api/snap.json")
  local v = wobble.load("rigid_api/snap.json")
  expect.eq(v:hash(), w:hash(), "same hash after load")
  expect.eq(#v:rigids(), 3)
  for _ = 1, 60 do w:step(); v:step() end
  expect.eq(v:hash(), w:hash(), "same future")
  local x1, y1 = w:rigids()[1]:position()
  local x2, y2 = v:rigids()[1]:position()
  expect.eq(x1, x2); expect.eq(y1, y2)
  -- a body added to the loaded world takes the removed one's slot, as in the original
  local n1 = w:rigid{ shape = "box" }
  local n2 = v:rigid{ shape = "box" }
  expect.eq(w:hash(), v:hash(), "slots and generations restored")
end)

test("a config's rigids section: as w:rigid takes them; errors name the key", function()
  local function write(name, rigids)
    local f = assert(io.open("rigid_api/" .. name, "wb"))
    f:write('{"format": "wobble-particles", "version": 1, "particles": [],\n "rigids": ', rigids, '}\n')
    f:close()
    return "rigid_api/" .. name
  end
  local w = assert(wobble.load(write("ok.json", '[{"shape": "capsule", "a": [0, 0, 0], "b": [2, 0, 0], "radius": 0.1, ' ..
                                               '"pos": [0, 1, 0], "mass": 2}, {"shape": "box", "half": [1, 1, 1]}]')))
  local rs = w:rigids()
  expect.eq(#rs, 2)
  local x, y = rs[1]:position()
  expect.eq(x, 1); expect.eq(y, 1)
  expect.eq(rs[1]:mass(), 2)
  -- the same world made in Lua hashes the same
  local u = wobble.world{}
  u:rigid{ shape = "capsule", a = {0, 0, 0}, b = {2, 0, 0}, radius = 0.1, pos = {0, 1, 0}, mass = 2 }
  u:rigid{ shape = "box", half = {1, 1, 1} }
  expect.eq(u:hash(), w:hash())
  local cases = {
    { '[{"shape": "box", "radius": 1}]', "radius" },
    { '[{"shape": "plane"}]', "not a rigid body shape" },
    { '[{"half": [1, 1, 1]}]', "shape" },
    { '[{"shape": "box", "mass": -1}]', "mass must be > 0" },
    { '[{"shape": "box", "bogus": 1}]', "bogus" },
    { '[{"shape": "sphere", "pos": [0, 0]}]', "pos" },
  }
  for k, c in ipairs(cases) do
    local v, err = wobble.load(write("bad" .. k .. ".json", c[1]))
    expect.eq(v, nil)
    expect.truthy(tostring(err):find(c[2], 1, true), "case " .. k .. ": " .. tostring(err))
    expect.truthy(tostring(err):find("rigids", 1, true), "names the section: " .. tostring(err))
  end
end)
