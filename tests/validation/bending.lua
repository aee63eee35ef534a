-- bending.lua: dihedral bending (w:bend, w:cloth{bend}) and break_force against
-- physics.
--
-- A bend keeps the angle between two triangles hinged on an edge (XPBD, compliance alpha
-- in rad/(N m)): at equilibrium each hinge carries a moment M = (theta - rest) / alpha,
-- whatever the substep h, because XPBD scales alpha by 1/h^2 (Macklin et al. 2016). Plain
-- PBD stiffness would not: its effective stiffness grows with the substeps.

local PI = math.pi

-- a strip clamped at x = 0 (its first two columns pinned), links rigid: only the bends
-- resist gravity. Returns the mean tip sag (m) after it settles (velocity drag, which
-- does not change the equilibrium, damps it in 5 s).
local function cantilever(substeps, bend)
  local w = wobble.world{ substeps = substeps, damping = 3 }
  local nx = 6
  local b = w:cloth{ origin = {0, 0, 0}, size = {1, 0.2}, res = {nx, 3}, mass = 0.1, compliance = 0, bend = bend }
  for j = 0, 2 do
    w:pin(b.particles[j * nx + 1])
    w:pin(b.particles[j * nx + 2])
  end
  w:run{ seconds = 5 }
  local s = 0
  for j = 0, 2 do
    local _, y = w:position(b.particles[j * nx + nx])
    s = s + y
  end
  return -s / 3, w
end

test("cantilever: tip sag independent of substeps at equal compliance", function()
  -- compliance 1 rad/(N m) bends the 1 m strip to a 0.2 m sag: the regime where compliance,
  -- not the solver's iteration count, sets the answer (alpha/h^2 dominates the generalized
  -- inverse mass w |grad theta|^2 at h = 1/600 s: 3.6e5 against ~2e4). The remaining
  -- difference between 10 and 40 substeps is the Gauss-Seidel residual of one iteration
  -- per substep, measured at 2.4%: 5% leaves margin without hiding a 1/h^2 error (a
  -- stiffness that scaled with h^2 would change the sag 16-fold).
  local s10, w = cantilever(10, 1)
  local s40 = cantilever(40, 1)
  expect.gt(s10, 0.05, "it bends")
  expect.near(s40, s10, 0.05 * s10, "sag at 40 substeps vs 10")
  local ke = w:energy()
  expect.lt(ke, 1e-5, "settled")
  -- the bends carry it: without them the strip hangs almost straight down (sag ~ 0.95 m)
  local free = cantilever(10, nil)
  expect.gt(free, 3 * s10, "without bends it droops far more")
  -- stiffer bends sag less, softer more (monotone in compliance)
  expect.lt(cantilever(10, 0.3), s10, "stiffer")
  expect.gt(cantilever(10, 3), s10, "softer")
end)

-- two triangles on a pinned hinge along x, wings free, links rigid; the wings start at
-- 90 degrees to each other. Gravity turns the pair about the hinge, but only the bend
-- keeps the angle between the wings: without it both hang straight down, folded over.
local function folded_pair(with_bend)
  local w = wobble.world{ damping = 2, substeps = 20 }
  local p1 = w:particle{ pos = {0, 1, 0}, mass = 0 }
  local p2 = w:particle{ pos = {1, 1, 0}, mass = 0 }
  local p3 = w:particle{ pos = {0.5, 1, 0.6}, mass = 0.5 }
  local p4 = w:particle{ pos = {0.5, 1.6, 0}, mass = 0.5 }
  for _, q in ipairs{ p3, p4 } do
    w:distance(p1, q)
    w:distance(p2, q)
  end
  local b = w:bend(p1, p2, p3, p4, { compliance = with_bend and 1e-4 or 1e6 })
  w:run{ seconds = 4 }
  return b, w
end

test("a bend holds a folded pair at its rest angle under gravity", function()
  local b, w = folded_pair(true)
  expect.near(math.abs(b:rest()), PI / 2, 1e-12, "rest = the angle at creation")
  -- the moment on the hinge is at most m g r = 0.5 * 9.81 * 0.6 ~ 3 N m per wing, so
  -- compliance 1e-4 gives at most 3e-4 rad; 2e-3 allows for the undamped residue
  expect.near(b:angle(), b:rest(), 2e-3, "angle held")
  -- the force readback is that moment: the two wings hang symmetric, each at 45 degrees
  -- from the vertical, so M = m g (0.6 sin 45) = 2.08 N m (2% for the residual motion)
  expect.near(b:force(), 0.5 * 9.81 * 0.6 * math.sin(PI / 4), 0.04, "force() = hinge moment, N m")
  local _, _, p3 = b:particles()
  local _, y3 = w:position(p3)
  expect.lt(y3, 1, "the pair turned under gravity (only the relative angle is kept)")
  -- practically no bend (compliance 1e6): the wings fold onto each other
  local nb = folded_pair(false)
  expect.gt(math.abs(nb:angle() - nb:rest()), 1, "without the bend the angle is lost")
end)

test("angle stays finite and continuous through flat and folded over", function()
  -- "rest reached" within a frame is XPBD's projection, exact at every substep. VBD's rigid
  -- bend, as its rigid link, keeps the error its sweep leaves and takes it back by 0.1% a
  -- substep (the stabilisation that keeps a clamped strip with rigid bends from blowing
  -- up; vbd.lua checks that strip): a wing set pi/2 off is 0.57 rad off after its first
  -- Newton step, 0.1 rad after a frame. So under VBD only the rest of this test applies.
  local projects = wobble.world{}:solver() ~= "vbd"
  for _, rest in ipairs{ 0, PI, -PI / 2 } do
    local w = wobble.world{ gravity = {0, 0, 0} }
    local p1 = w:particle{ pos = {0, 0, 0}, mass = 0 }
    local p2 = w:particle{ pos = {1, 0, 0}, mass = 0 }
    local p3 = w:particle{ pos = {0.5, 0, 1}, mass = 0 }
    local p4 = w:particle{ pos = {0.5, 0, -1} }
    local b = w:bend(p1, p2, p3, p4, { compliance = 0, rest = rest })
    -- the wing p4 swept once round the hinge, exactly through flat (0) and folded (pi)
    local prev
    for k = 0, 72 do
      local phi = -PI + k * PI / 36
      w:set_position(p4, 0.5, math.sin(phi), -math.cos(phi))
      local a = b:angle()
      expect.truthy(a == a and math.abs(a) <= PI, "finite angle at phi = " .. phi)
      if prev and k < 72 then expect.lt(math.abs(a - prev), PI / 36 + 1e-9, "continuous") end
      prev = a
      -- one frame from here: the projection meets the rest angle (taking the short way)
      w:step()
      local x, y, z = w:position(p4)
      expect.truthy(x == x and y == y and z == z, "finite position")
      local d = math.abs(b:angle() - rest)
      if projects then expect.lt(math.min(d, 2 * PI - d), 1e-6, "rest reached") end
    end
    -- degenerate: the wing on the hinge line has no angle; nothing turns NaN
    w:set_position(p4, 2, 0, 0)
    expect.truthy(b:angle() ~= b:angle(), "angle() is NaN while degenerate")
    w:step()
    local x = w:position(p4)
    expect.truthy(x == x, "position finite")
    expect.eq(w:warnings(), 0, "no warning")
  end
end)

-- a mass m on a rigid link from a pinned particle: the link pulls m g, exactly, from the
-- first substep on (it starts at rest at its rest length), so break_force decides at once
local function hanging(break_force)
  local w = wobble.world{}
  local top = w:particle{ pos = {0, 1, 0}, mass = 0 }
  local m = w:particle{ pos = {0, 0.5, 0}, mass = 2 }
  local c = w:distance(top, m, { break_force = break_force })
  local broke = 0
  w:run{ frames = 120, on_frame = function(w) broke = broke + #w:breaks() end }
  return c, broke, w
end

test("break_force: a link breaks at the force it carries", function()
  local mg = 2 * 9.81
  local c, broke = hanging(1.02 * mg)
  expect.falsy(c:broken(), "2% above m g holds")
  expect.eq(broke, 0)
  expect.near(c:force(), mg, 1e-6 * mg, "force() = m g")
  local c2, broke2, w = hanging(0.98 * mg)
  expect.truthy(c2:broken(), "2% below m g breaks")
  expect.eq(broke2, 1, "reported once, as a break")
  local _, y = w:position(select(2, c2:particles()))
  expect.lt(y, 0, "and the mass falls")
  -- break_strain alone never fires on a rigid link carrying the same load. XPBD projects
  -- it exactly; VBD's rigid link is a penalty k = 8 m / h^2 (its ends' inertia) until its
  -- multiplier has the load, so its first substep stretches it by m g / k = g h^2 / 8 and
  -- it keeps 0.999 of that a substep: 6.8e-6 of its 0.5 m at h = 1/600 s (docs/physics.md,
  -- "VBD"); the limit is then 1e-5, still far below any stretch a material would have
  local w3 = wobble.world{}
  local top = w3:particle{ pos = {0, 1, 0}, mass = 0 }
  local m = w3:particle{ pos = {0, 0.5, 0}, mass = 2 }
  local c3 = w3:distance(top, m, { break_strain = w3:solver() == "vbd" and 1e-5 or 1e-6 })
  w3:run{ frames = 120 }
  expect.falsy(c3:broken(), "a rigid link barely stretches")
  -- builders pass it on: a rope's top link carries the whole rope, the next one less.
  -- 20 iterations: one Gauss-Seidel pass over a chain starting at rest overshoots the top
  -- link's force by 2% in the first frame (measured); 20 converge it to the static value
  local w4 = wobble.world{ iterations = 20 }
  local rope = w4:rope{ from = {0, 1, 0}, to = {0, 0, 0}, segments = 4, mass = 1, break_force = 0.9 * 9.81 }
  w4:pin(rope.particles[1])
  w4:step()
  local broken = {}
  for _, d in ipairs(w4:distances()) do broken[#broken + 1] = d:broken() and 1 or 0 end
  -- the top link holds 4/5 of the 1 kg (the pinned particle's share is its own): 0.8 g
  -- < 0.9 g, so nothing breaks; at 0.7 g the top link alone goes
  expect.eq(table.concat(broken), "0000")
  local w5 = wobble.world{ iterations = 20 }
  local rope5 = w5:rope{ from = {0, 1, 0}, to = {0, 0, 0}, segments = 4, mass = 1, break_force = 0.7 * 9.81 }
  w5:pin(rope5.particles[1])
  w5:step()
  broken = {}
  for _, d in ipairs(w5:distances()) do broken[#broken + 1] = d:broken() and 1 or 0 end
  expect.eq(table.concat(broken), "1000")
end)

test("bends and break_force round-trip through w:save / wobble.load exactly", function()
  local w = wobble.world{ threads = 2 }
  local c = w:cloth{ origin = {-0.5, 1, -0.5}, size = {1, 1}, res = {10, 10}, compliance = 1e-6, bend = 1e-2 }
  w:pin(c.particles[1])
  local top = w:particle{ pos = {2, 2, 0}, mass = 0 }
  local m = w:particle{ pos = {2, 1.5, 0} }
  w:distance(top, m, { break_force = 50 })
  w:bend(c.particles[1], c.particles[2], c.particles[11], top, { compliance = 0.5, damping = 0.1, rest = 0.25 })
  w:run{ frames = 10 }
  w:save("bend_snapshot.json")
  local w2 = wobble.load("bend_snapshot.json")
  expect.eq(#w2:bends(), #w:bends())
  expect.eq(w2:hash(), w:hash())
  local b, b2 = w:bends()[#w:bends()], w2:bends()[#w2:bends()]
  expect.eq(b2:rest(), 0.25)
  expect.eq(b2:rest(), b:rest())
  w:run{ frames = 20 }
  w2:run{ frames = 20 }
  expect.eq(w2:hash(), w:hash(), "same future")
  expect.eq(select(2, w2:energy()), select(2, w:energy()), "same elastic energy")
end)

test("JSON particle config: bend entries (rest measured when absent) and break_force", function()
  local f = assert(io.open("bend_config.json", "w"))
  f:write([[{"format": "wobble-particles", "version": 1,
    "particles": [{"position": [0, 1, 0], "pinned": true}, {"position": [1, 1, 0], "pinned": true},
                  {"position": [0.5, 1, 1]}, {"position": [0.5, 2, 0]}],
    "constraints": [{"type": "distance", "particles": [0, 2], "break_force": 1000},
                    {"type": "bend", "particles": [0, 1, 2, 3], "compliance": 0.001},
                    {"type": "distance", "particles": [1, 2]},
                    {"type": "distance", "particles": [0, 3]}, {"type": "distance", "particles": [1, 3]}]}]])
  f:close()
  local w = wobble.world{}
  w:load_particles("bend_config.json")
  expect.eq(#w:bends(), 1)
  expect.eq(#w:distances(), 4)
  expect.near(math.abs(w:bends()[1]:rest()), PI / 2, 1e-12, "rest measured from the positions")
  w:run{ frames = 60 }
  expect.near(w:bends()[1]:angle(), w:bends()[1]:rest(), 0.01, "held")
  w:save("bend_config_out.json")
  local w2 = wobble.load("bend_config_out.json")
  expect.eq(w2:hash(), w:hash())
end)

test("w:energy(): a bend bent by C stores C^2 / (2 alpha)", function()
  -- immovable particles and no gravity: the potential is the bend's alone
  local w = wobble.world{ gravity = {0, 0, 0} }
  local p = {}
  for i, x in ipairs{ {0, 0, 0}, {1, 0, 0}, {0.5, 0, 1}, {0.5, 0, -1} } do p[i] = w:particle{ pos = x, mass = 0 } end
  local b = w:bend(p[1], p[2], p[3], p[4], { compliance = 0.5 })
  expect.eq(select(2, w:energy()), 0, "at rest: none")
  local phi = 0.3 -- the wing p4 turned by phi about the hinge (the x axis)
  w:set_position(p[4], 0.5, math.sin(phi), -math.cos(phi))
  expect.near(math.abs(b:angle()), phi, 1e-12)
  expect.near(select(2, w:energy()), phi * phi / (2 * 0.5), 1e-12, "C^2 / (2 alpha)")
  -- a rigid bend (compliance 0) stores none: its potential is not defined
  local w2 = wobble.world{ gravity = {0, 0, 0} }
  local q = {}
  for i, x in ipairs{ {0, 0, 0}, {1, 0, 0}, {0.5, 0, 1}, {0.5, 0.3, -1} } do q[i] = w2:particle{ pos = x, mass = 0 } end
  w2:bend(q[1], q[2], q[3], q[4], { compliance = 0, rest = 0 })
  expect.eq(select(2, w2:energy()), 0)
end)
