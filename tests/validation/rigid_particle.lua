-- rigid_particle.lua: two-way particle-rigid contacts: a particle's sphere
-- against a body's shape, projected with the particle's inverse mass and the body's
-- generalized inverse mass at the point (Müller et al. 2020, eq. 2-3).
--
-- Momentum. Every impulse acts on the body at the particle's centre, equal and opposite
-- to the particle's: the total linear momentum changes only by round-off (measured 1e-13
-- N s on a momentum of 1 N s, tested at 1e-11). Angular momentum about the origin
-- (x × m v with v = (x - x_prev) / h) changes by (x_prev,p - x_prev,b - arm) × J / h for a
-- positional impulse J applied with lever arm `arm`; rigid_particle.c uses the particle's
-- offset at the substep's start as the arm, which cancels it: for a sphere (isotropic
-- inertia) the change is round-off (1e-14, tested at 1e-11), spin from friction included.
-- A box's world inertia turns with it while a correction turns it, a second-order term
-- (|dtheta| |omega| I): measured 3e-5 on 0.2 N m s, tested at 1e-4.

local g = 9.81

local function momenta(w)
  local p = { w:momentum() }
  local l = { w:angular_momentum() }
  return p, l
end

local function diff(a, b)
  return math.max(math.abs(a[1] - b[1]), math.abs(a[2] - b[2]), math.abs(a[3] - b[3]))
end

test("a particle and a free sphere exchange momentum exactly", function()
  for _, c in ipairs{ { y = 0, mu = 0 }, { y = 0.2, mu = 0.5 } } do
    local w = wobble.world{ gravity = {0, 0, 0}, substeps = 10 }
    w:particle{ pos = {-1, c.y, 0.05}, vel = {2, 0, 0}, mass = 0.5, radius = 0.05 }
    local s = w:rigid{ shape = "sphere", radius = 0.3, mass = 2, friction = c.mu }
    local p0, l0 = momenta(w)
    for _ = 1, 60 do w:step() end
    local p1, l1 = momenta(w)
    expect.lt(diff(p0, p1), 1e-11, "linear momentum, y " .. c.y)
    expect.lt(diff(l0, l1), 1e-11, "angular momentum, y " .. c.y)
    local vx = s:velocity()
    expect.gt(vx, 0.3, "the sphere was pushed")
    if c.mu > 0 then
      local _, _, oz = s:angular_velocity()
      expect.lt(oz, -0.5, "a glancing hit with friction spins it")
    end
  end
end)

test("an off-centre hit spins a free box; momentum kept", function()
  for _, mu in ipairs{ 0, 0.5 } do
    local w = wobble.world{ gravity = {0, 0, 0}, substeps = 10 }
    w:particle{ pos = {-1, 0.2, 0.05}, vel = {2, 0, 0}, mass = 0.5, radius = 0.05 }
    local b = w:rigid{ shape = "box", half = {0.3, 0.3, 0.3}, mass = 2, friction = mu, rotation = {0.9, 0.1, 0.2, 0.05} }
    local p0, l0 = momenta(w)
    for _ = 1, 60 do w:step() end
    local p1, l1 = momenta(w)
    expect.lt(diff(p0, p1), 1e-11, "linear momentum, mu " .. mu)
    expect.lt(diff(l0, l1), 1e-4, "angular momentum, mu " .. mu)
    local ox, oy, oz = b:angular_velocity()
    expect.gt(math.sqrt(ox * ox + oy * oy + oz * oz), 0.5, "spun")
  end
end)

-- Head on, centred, perfectly inelastic (restitution 0): both end at m v0 / (m + M).
-- Exact for the positional solve (one contact: lambda = depth / (w_p + 1/M)) and the
-- velocity pass; measured 1e-13 relative, tested at 1e-9.
test("a light particle barely moves a heavy box", function()
  local m, M, v0 = 0.01, 10, 3
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = 10 }
  local p = w:particle{ pos = {-1, 0, 0}, vel = {v0, 0, 0}, mass = m, radius = 0.05 }
  local b = w:rigid{ shape = "box", half = {0.3, 0.3, 0.3}, mass = M }
  for _ = 1, 60 do w:step() end
  local vb = b:velocity()
  local vp = w:velocity(p)
  expect.rel(vb, m * v0 / (m + M), 1e-9, "box")
  expect.rel(vp, m * v0 / (m + M), 1e-9, "particle moves with it")
  local ox, oy, oz = b:angular_velocity()
  expect.lt(math.abs(ox) + math.abs(oy) + math.abs(oz), 1e-12, "no spin")
end)

-- The particle's contact force reads m g (its multiplier over h^2) and nothing moves:
-- the total momentum stays zero while gravity pulls (M + m) g, so the ground's contact
-- carries (M + m) g (measured 2e-14 N s, tested at 1e-11). The particle's push lands on the box after the ground's in each
-- substep: the box sits m g h^2 / M (6.8e-6 m) low, tested at 2e-5.
test("a particle resting on a box resting on the ground", function()
  local m, M = 0.5, 2
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  w:collider{ shape = "plane" }
  local b = w:rigid{ shape = "box", half = {0.3, 0.2, 0.3}, mass = M, pos = {0, 0.2, 0} }
  local p = w:particle{ pos = {0.1, 0.45, 0}, mass = m, radius = 0.05 }
  local worst = 0
  for f = 1, 300 do
    w:step()
    local px, py, pz = w:momentum()
    -- (the first frame settles the box's m g h^2 / M: 5e-9 N s)
    if f > 1 then worst = math.max(worst, math.abs(px), math.abs(py), math.abs(pz)) end
  end
  expect.lt(worst, 1e-11, "momentum stays zero: the ground carries (M + m) g")
  local _, py = w:position(p)
  local _, by = b:position()
  expect.near(by, 0.2, 2e-5, "box on the ground")
  expect.near(py, 0.45, 2e-5, "particle on the box")
  local c = w:rigid_contacts()
  expect.eq(#c, 1, "one contact")
  expect.eq(c[1].particle, p)
  expect.eq(c[1].body, b)
  expect.rel(c[1].force, m * g, 1e-9, "its force is the particle's weight")
  expect.near(c[1].normal[2], 1, 1e-12, "normal out of the box's top")
  local st = w:stats()
  expect.eq(st.rigids, 1)
  expect.eq(st.rigid_contacts, 1)
end)

-- A 5 kg box dropped 10 cm onto a soft block of 2 kg: it sinks in until the block holds
-- it. Checked after 5 s: no particle inside the box past 1e-3 m (1.6% of the radius: a
-- body's contacts are solved together and leave what the others' pushes turned; measured
-- 2e-4), the block under the box 5 mm lower than the same block alone (1 cm measured),
-- the box well above the ground and at rest.
test("a rigid box dropped on a soft block comes to rest on it", function()
  local function scene(with_box)
    local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
    w:collider{ shape = "plane", friction = 0.5 }
    w:lattice{ min = {-0.5, 0.0625, -0.5}, max = {0.5, 0.5625, 0.5}, res = {9, 5, 9}, mass = 2,
               compliance = 5e-3, damping = 0.1, friction = 0.5 }
    local b = with_box and w:rigid{ shape = "box", half = {0.3, 0.1, 0.3}, mass = 5, pos = {0, 0.8, 0}, friction = 0.5 }
    for _ = 1, 300 do w:step() end
    local top = -math.huge
    for i = 1, w:particle_count() do
      local x, y, z = w:position(i)
      if math.abs(x) < 0.1 and math.abs(z) < 0.1 then top = math.max(top, y) end
    end
    return w, b, top
  end
  local _, _, top0 = scene(false)
  local w, b, top = scene(true)
  local worst = math.huge
  for i = 1, w:particle_count() do
    worst = math.min(worst, b:distance(w:position(i)) - w:radius(i))
  end
  expect.gt(worst, -1e-3, "no particle inside the box")
  expect.lt(top, top0 - 5e-3, "the block gives under the box")
  local _, y = b:position()
  expect.gt(y - 0.1, 0.5, "held above the ground")
  local vx, vy, vz = b:velocity()
  expect.lt(math.sqrt(vx * vx + vy * vy + vz * vz), 0.02, "at rest")
end)

-- A cloth pinned at its corners catches a 1 kg box dropped from 1 m above it: after the
-- first dip the box stays on the sheet (after 2 s between 0.6 and 1.05 m: the sheet's
-- sag and bounce) and ends nearly at rest (world drag 1/s). Particles inside the box by up to 1e-3 m are allowed (the cloth's
-- tension pulls back on what the box's contacts pushed out; measured 3e-4).
test("a cloth trampoline catches a falling box", function()
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10, damping = 1 }
  local c = w:cloth{ origin = {-1, 1, -1}, size = {2, 2}, res = {21, 21}, mass = 1, compliance = 1e-4 }
  c:pin_where(function(x, _, z) return math.abs(math.abs(x) - 1) < 1e-9 and math.abs(math.abs(z) - 1) < 1e-9 end)
  local b = w:rigid{ shape = "box", half = {0.2, 0.2, 0.2}, mass = 1, pos = {0.1, 2, 0.05}, friction = 0.3 }
  local lo, hi = math.huge, -math.huge
  for f = 1, 300 do
    w:step()
    if f > 120 then
      local _, y = b:position()
      lo, hi = math.min(lo, y), math.max(hi, y)
    end
  end
  expect.gt(lo, 0.6, "caught")
  expect.lt(hi, 1.05, "stays on the sheet")
  local _, vy = b:velocity()
  expect.lt(math.abs(vy), 0.3, "settling")
  local worst = math.huge
  for i = 1, w:particle_count() do
    worst = math.min(worst, b:distance(w:position(i)) - w:radius(i))
  end
  expect.gt(worst, -1e-3, "no particle inside the box")
end)

test("no rigid bodies: no candidates, nothing counted", function()
  local w = wobble.world{}
  w:particle{ pos = {0, 0, 0} }
  w:step()
  local st = w:stats()
  expect.eq(st.rigids, 0)
  expect.eq(st.rigid_contacts, 0)
  expect.eq(#w:rigid_contacts(), 0)
end)
