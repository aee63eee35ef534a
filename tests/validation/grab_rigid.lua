-- grab_rigid.lua: grabbing rigid bodies: w:grab(rb, target, {at}).
--
-- The grab is the point constraint C = x_b - t (x_b: the body's point `at`, fixed in its
-- frame), solved in 3D with the body's response matrix K = 1/M E - [d]x I^-1 [d]x at the
-- point (as attachments to bodies). Compliance 0 removes the whole violation every
-- substep: at rest the prediction adds g h^2 to the point and the correction takes exactly
-- that away, so lambda = M g h^2 and g:force() = lambda / h^2 = M g to round-off.

local g = 9.81

local function world(opts)
  local o = { gravity = {0, -g, 0}, substeps = 20 }
  for k, v in pairs(opts or {}) do o[k] = v end
  return wobble.world(o)
end

test("a box grabbed at its centre hangs at the target and g:force() reads M g", function()
  local M = 3
  local w = world()
  local rb = w:rigid{ shape = "box", half = {0.2, 0.1, 0.3}, mass = M, pos = {0, 2, 0} }
  local gr = w:grab(rb, {0, 2, 0})
  w:run{ seconds = 2 }
  -- on the target at every substep's end: coordinate round-off only
  local x, y, z = rb:position()
  expect.near(x, 0, 1e-12, "centre x")
  expect.near(y, 2, 1e-12, "centre y")
  expect.near(z, 0, 1e-12, "centre z")
  local f, fx, fy, fz = gr:force()
  -- lambda = M g h^2 per substep, read back / h^2: rounding of h^2 and of the sums, ~1e-11
  expect.rel(f, M * g, 1e-9, "|F| = M g")
  expect.rel(fy, M * g, 1e-9, "the force on the body points up")
  expect.near(fx, 0, 1e-9, "no sideways force")
  expect.near(fz, 0, 1e-9, "no sideways force")
  local px, py, pz = gr:point()
  expect.near(py, 2, 1e-12, "g:point() is the body's centre")
  expect.near(px, 0, 1e-12, "g:point() is the body's centre")
  expect.near(pz, 0, 1e-12, "g:point() is the body's centre")
  expect.eq(gr:particle(), nil, "a body's grab has no particle")
  expect.eq(gr:body(), rb, "g:body() is the grabbed body")
  expect.truthy(tostring(gr):find("rigid body"), "tostring names the body")
  local wx, wy, wz = rb:angular_velocity()
  expect.near(wx * wx + wy * wy + wz * wz, 0, 1e-24, "grabbed at the centre: no spin")
end)

test("grabbed at a corner a box swings and settles with its centre of mass below the grab point", function()
  local M, d, seconds = 3, 2, 10
  local at = {0.2, 0.1, 0.3}
  local t = {0.2, 2.1, 0.3}
  -- the centre starts |at| away from straight below the target (the corner on it)
  local w = world{ damping = d }
  local rb = w:rigid{ shape = "box", half = {0.2, 0.1, 0.3}, mass = M, pos = {0, 2, 0} }
  local gr = w:grab(rb, t, { at = at })
  local moved = 0
  for _ = 1, 10 do
    w:run{ frames = 6 }
    local x = rb:position()
    moved = math.max(moved, math.abs(x))
  end
  expect.gt(moved, 0.05, "it swings (the centre moves towards below the corner)")
  w:run{ seconds = seconds - 1 }
  -- static equilibrium: the weight through the grab point. The world's velocity drag d
  -- damps the swing at least as exp(-d t / 2) from its first amplitude, |at| = 0.37 m:
  -- 2 |at| exp(-d t/2) = 3.4e-5 m after 10 s (measured: 1.4e-5)
  local L = math.sqrt(at[1] ^ 2 + at[2] ^ 2 + at[3] ^ 2)
  local tol = 2 * L * math.exp(-d * seconds / 2)
  local x, y, z = rb:position()
  expect.near(x, t[1], tol, "centre x below the grab point")
  expect.near(z, t[3], tol, "centre z below the grab point")
  expect.near(y, t[2] - L, tol, "the centre |at| below the grab point")
  -- the grab point itself is on the target (compliance 0)
  local px, py, pz = gr:point()
  expect.near(px, t[1], 1e-9, "the grabbed corner on the target")
  expect.near(py, t[2], 1e-9, "the grabbed corner on the target")
  expect.near(pz, t[3], 1e-9, "the grabbed corner on the target")
  expect.rel(gr:force(), M * g, 1e-3, "at rest the grab carries the weight")
end)

test("g:move carries the body, g:release lets it fall freely: v = g t", function()
  local w = world{ substeps = 10 }
  local rb = w:rigid{ shape = "sphere", radius = 0.2, mass = 2, pos = {0, 1, 0} }
  local gr = w:grab(rb, {0, 1, 0})
  w:run{ frames = 30 }
  gr:move(0.5, 1, 0)
  w:run{ frames = 2 }
  local x = rb:position()
  expect.near(x, 0.5, 1e-12, "moved to the new target")
  w:run{ frames = 30 }
  local _, vy = rb:velocity()
  expect.near(vy, 0, 1e-9, "held at rest")
  gr:release()
  expect.falsy(gr:valid(), "released")
  expect.error(function() gr:force() end, "grab was released")
  expect.eq(w:stats().grabs, 0)
  local frames = 45
  w:run{ frames = frames }
  -- symplectic Euler: v = g n h exactly for an untouched body (round-off only), and the
  -- rest velocity it had was round-off too
  _, vy = rb:velocity()
  expect.rel(vy, -g * frames / 60, 1e-9, "v = g t after the release")
end)

test("removing the body ends its grabs; errors name the argument and change nothing", function()
  local w = world()
  local rb = w:rigid{ shape = "box", half = {0.1, 0.1, 0.1}, pos = {0, 1, 0} }
  local other = world()
  local orb = other:rigid{ shape = "box", half = {0.1, 0.1, 0.1}, pos = {0, 1, 0} }
  local p = w:particle{ pos = {1, 1, 0} }
  local h0 = w:hash()
  expect.error(function() w:grab(rb, {0, 1, 0}, { at = {0, 0 / 0, 0} }) end, "at")
  expect.error(function() w:grab(rb, {0, 1, 0}, { at = {0, 0} }) end, "at")
  expect.error(function() w:grab(rb, {0, 1, 0}, { compliance = -1 }) end, "compliance")
  expect.error(function() w:grab(rb, {0, 1 / 0, 0}) end, "bad argument #2 to 'grab'")
  expect.error(function() w:grab(orb, {0, 1, 0}) end, "bad argument #1 to 'grab' (the rigid body belongs to another world")
  expect.error(function() w:grab(p, {0, 1, 0}, { at = {0, 0, 0} }) end, "at")
  expect.error(function() w:grab("x", {0, 1, 0}) end, "particle id or rigid body expected")
  expect.eq(w:hash(), h0, "refused calls change nothing")
  expect.eq(w:stats().grabs, 0)
  local gr = w:grab(rb, {0, 1, 0}, { at = {0.1, 0.1, 0.1} })
  expect.truthy(w:hash() ~= h0, "a grab changes the hash")
  rb:remove()
  expect.falsy(gr:valid(), "its body removed: the grab is over")
  expect.eq(#w:grabs(), 0)
  expect.error(function() gr:move(0, 0, 0) end, "rigid body removed")
  expect.error(function() w:grab(rb, {0, 1, 0}) end, "bad argument #1 to 'grab' (the rigid body was removed)")
  w:run{ frames = 2 } -- the step retires it
  expect.eq(w:stats().grabs, 0)
end)

test("save and load keep a body's grab exactly; configs name the body and the point", function()
  local w = world{ substeps = 10 }
  local dead = w:rigid{ shape = "sphere", radius = 0.1, pos = {3, 0, 0} }
  local rb = w:rigid{ shape = "box", half = {0.1, 0.2, 0.1}, pos = {0, 0, 0}, angular_velocity = {1, 2, 0} }
  dead:remove() -- a removed slot before the grabbed body: slots, not ranks, are saved
  local gr = w:grab(rb, {0, 0.5, 0}, { at = {0.1, 0.2, -0.1}, compliance = 1e-4 })
  w:run{ frames = 20 }
  gr:move(0.3, 0.4, 0) -- mid-sweep: "from" differs from "target" in the snapshot
  expect.eq(w:save("grab_rigid/snap.json"), true)
  local v = assert(wobble.load("grab_rigid/snap.json"))
  expect.eq(v:hash(), w:hash())
  for _ = 1, 30 do w:step() v:step() end
  expect.eq(v:hash(), w:hash(), "identical futures")
  local vg = v:grabs()[1]
  expect.eq(vg:particle(), nil)
  expect.near(select(1, vg:target()), 0.3, 0)
  -- a particle config: "rigid" counts the file's "rigids", "at" the point in its frame
  local f = assert(io.open("grab_rigid/cfg.json", "w"))
  f:write([[{"format": "wobble-particles", "version": 1,
    "particles": [{"position": [5, 0, 0], "pinned": true}],
    "rigids": [{"shape": "box", "half": [0.1, 0.1, 0.1], "pos": [0, -0.2, 0], "mass": 2}],
    "grabs": [{"rigid": 0, "at": [0, 0.1, 0], "target": [0, 0, 0]}]}]])
  f:close()
  local c = assert(wobble.load("grab_rigid/cfg.json"))
  c:run{ frames = 30 }
  expect.rel(c:grabs()[1]:force(), 2 * g, 1e-6, "the loaded grab holds the box by its top")
  local bad = assert(io.open("grab_rigid/bad.json", "w"))
  bad:write([[{"format": "wobble-particles", "version": 1,
    "particles": [{"position": [0, 0, 0]}],
    "rigids": [{"shape": "sphere", "radius": 0.2, "pos": [0, -0.2, 0]}],
    "grabs": [{"particle": 0, "at": [0, 0, 0], "target": [0, 0, 0]}]}]])
  bad:close()
  local ok, err = wobble.load("grab_rigid/bad.json")
  expect.eq(ok, nil)
  expect.truthy(tostring(err):find("grabs[0].at", 1, true), "the error names the key: " .. tostring(err))
end)
