-- attach_rigid.lua: particles attached to rigid bodies: the body is
-- pulled back, two-way.
--
-- The attachment is the point constraint C = x_p - t (t: the body's point fixed in its
-- frame), solved in 3D with the body's response matrix at the point, K = (w_p + 1/M) E -
-- [d]x I^-1 [d]x (Müller et al. 2020's generalized inverse mass, as a matrix). Each
-- substep removes the whole violation, so at rest the multiplier is exactly the weight's
-- impulse and force() reads M g.

local g = 9.81

-- a sphere of radius R hung from a pinned particle on its surface: a physical pendulum
-- about that point, d = R from the centre, I_p = (2/5 + 1) M R^2
local function pendulum(R, M, th0, substeps)
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = substeps or 20 }
  local p = w:particle{ pos = {0, 0, 0}, mass = 1 }
  w:pin(p)
  local s = w:rigid{ shape = "sphere", radius = R, mass = M, pos = {R * math.sin(th0), -R * math.cos(th0), 0} }
  return w, s, w:attach(p, s)
end

test("a sphere hung from a point on its surface swings with the physical pendulum's period", function()
  local R, M = 0.2, 2
  local w, s = pendulum(R, M, 0.05)
  local last, ups = nil, {}
  for f = 1, 600 do
    w:step()
    local x = s:position()
    if last and last < 0 and x >= 0 then ups[#ups + 1] = f end
    last = x
  end
  expect.ge(#ups, 8, "upward zero crossings in 10 s")
  -- crossings are read to the frame (1/60 s) over 8 periods: 0.2 % of 8.5 s; the small
  -- amplitude (0.05 rad) lengthens the period by th0^2/16 = 0.02 %: 1 % holds both
  local T = (ups[#ups] - ups[1]) / (#ups - 1) / 60
  expect.rel(T, 2 * math.pi * math.sqrt(1.4 * R / g), 0.01, "period 2 pi sqrt(I_p / (M g d))")
  -- its own spin follows the swing: the point does not slide (v = omega x (c - pivot))
  local vx = s:velocity()
  local _, _, oz = s:angular_velocity()
  local _, y = s:position()
  expect.near(vx, -oz * y, 1e-3 * math.abs(vx) + 1e-6, "the centre moves as the body turns about the pivot")
end)

test("at rest the attachment carries the body's weight, and a compliant one sags by M g alpha", function()
  local R, M = 0.2, 2
  local w, s, a = pendulum(R, M, 0)
  for _ = 1, 60 do w:step() end
  local f, fx, fy, fz = a:force()
  expect.rel(f, M * g, 1e-9, "|F| = M g")
  expect.rel(fy, -M * g, 1e-9, "pulls the pinned particle down towards the body")
  expect.near(fx, 0, 1e-9); expect.near(fz, 0, 1e-9)
  local _, y = s:position()
  expect.near(y, -R, 1e-9, "hangs where it was attached")
  -- compliant: a zero-length spring of stiffness 1/alpha (XPBD: exact at rest, any h)
  local alpha = 1e-3
  local w2 = wobble.world{ gravity = {0, -g, 0}, substeps = 20 }
  local p2 = w2:particle{ pos = {0, 0, 0}, mass = 1 }
  w2:pin(p2)
  local s2 = w2:rigid{ shape = "box", half = {0.1, 0.2, 0.1}, mass = M, pos = {0, -0.2, 0} }
  local a2 = w2:attach(p2, s2, { compliance = alpha })
  w2:run{ seconds = 20 }  -- the spring's bounce dies out by the XPBD's own damping... slowly
  local _, y2 = s2:position()
  expect.near(y2, -0.2 - M * g * alpha, 2e-4, "sags by M g alpha")
  expect.rel(a2:force(), M * g, 0.02, "|F| = M g")
end)

-- a particle (0.5 kg) tied to a tumbling free box (3 kg), no gravity, for 2 s
local function tied(substeps)
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = substeps }
  local p = w:particle{ pos = {0.5, 0.3, 0.1}, mass = 0.5, vel = {0, 2, -1} }
  local b = w:rigid{ shape = "box", half = {0.3, 0.2, 0.1}, mass = 3, pos = {0, 0, 0},
                     vel = {0.2, -0.1, 0}, angular_velocity = {0.5, 1, -2} }
  w:attach(p, b)
  local m0, l0 = { w:momentum() }, { w:angular_momentum() }
  for _ = 1, 120 do w:step() end
  local m1, l1 = { w:momentum() }, { w:angular_momentum() }
  local dm, dl, norm = 0, 0, 0
  for k = 1, 3 do
    dm = math.max(dm, math.abs(m1[k] - m0[k]))
    dl = math.max(dl, math.abs(l1[k] - l0[k]))
    norm = norm + l0[k] ^ 2
  end
  return dm, dl, math.sqrt(norm), w:position(p), b
end

test("a particle and a free body pulling on each other keep momentum, and angular momentum to first order in h", function()
  local dm, dl, L = tied(10)
  -- every correction is an equal and opposite impulse: momentum exact up to the
  -- round-off of order-1 quantities summed over 1,200 substeps
  expect.lt(dm, 1e-10, "momentum")
  -- the impulses act on one line (the body's at the particle), but velocities come from
  -- poses after a first-order turn (q += 1/2 [theta, 0] q): angular momentum is kept to
  -- O(h). Measured 0.5 % of |L| at h = 1/600 s and four times less at h/4
  expect.lt(dl, 0.02 * L, "angular momentum within 2 % at 10 substeps")
  local dm4, dl4 = tied(40)
  expect.lt(dm4, 1e-10, "momentum, 40 substeps")
  expect.lt(dl4, dl / 3, "angular momentum error falls with h (first order)")
end)

test("a ball on a rope hangs the rope's length plus its radius below the pin", function()
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 20, iterations = 2 }
  local rope = w:rope{ from = {0, 2, 0}, to = {0, 1, 0}, segments = 10, mass = 0.05 }
  w:pin(rope.first)
  local last = rope.first + rope.count - 1
  local ball = w:rigid{ shape = "sphere", radius = 0.15, mass = 2, pos = {0, 0.85, 0} }
  w:attach(last, ball)
  w:run{ seconds = 6 }
  local x, y = ball:position()
  -- the ball weighs 40 times the rope: Gauss-Seidel over a chain with that mass ratio
  -- leaves the links stretched (1.7 % here at 20 substeps, 2 iterations; PBD's known
  -- weakness with mass ratios), so: below pin - L - R, by less than 3 % of L
  expect.le(y, 2 - 1 - 0.15 + 1e-9, "centre at pin - L - R or below")
  expect.ge(y, 2 - 1.03 - 0.15, "the rope stretched by less than 3 %")
  expect.near(x, 0, 1e-6, "hangs straight")
end)

test("save and load keep attachments to rigid bodies exactly", function()
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  local p = w:particle{ pos = {0, 0, 0}, mass = 1 }
  w:pin(p)
  local dead = w:rigid{ shape = "sphere", radius = 0.1, pos = {3, 0, 0} }
  local s = w:rigid{ shape = "box", half = {0.1, 0.1, 0.1}, pos = {0.05, -0.1, 0} }
  dead:remove()  -- a removed slot before the attached body: slots, not ranks, are saved
  w:attach(p, s, { compliance = 1e-4 })
  w:run{ frames = 30 }
  expect.eq(w:save("attach_rigid/snap.json"), true)
  local v = assert(wobble.load("attach_rigid/snap.json"))
  expect.eq(v:hash(), w:hash())
  for _ = 1, 30 do w:step() v:step() end
  expect.eq(v:hash(), w:hash(), "identical futures")
  -- a particle config names the body by its place in "rigids"
  local f = assert(io.open("attach_rigid/cfg.json", "w"))
  f:write([[{"format": "wobble-particles", "version": 1,
    "particles": [{"position": [0, 0, 0], "pinned": true}],
    "rigids": [{"shape": "sphere", "radius": 0.2, "pos": [0, -0.2, 0], "mass": 2}],
    "attachments": [{"particle": 0, "rigid": 0}]}]])
  f:close()
  local c = assert(wobble.load("attach_rigid/cfg.json"))
  c:run{ frames = 30 }
  local a = c:attachments()[1]
  expect.rel(a:force(), 2 * g, 1e-6, "the loaded attachment holds the sphere")
  local bad = assert(io.open("attach_rigid/bad.json", "w"))
  bad:write([[{"format": "wobble-particles", "version": 1,
    "particles": [{"position": [0, 0, 0]}],
    "rigids": [{"shape": "sphere", "radius": 0.2, "pos": [0, -0.2, 0]}],
    "attachments": [{"particle": 0, "rigid": 1}]}]])
  bad:close()
  local ok, err = wobble.load("attach_rigid/bad.json")
  expect.eq(ok, nil)
  expect.truthy(tostring(err):find("attachments[0].rigid", 1, true), "the error names the key: " .. tostring(err))
end)

test("a particle attached inside a body does not collide with it; other bodies still do", function()
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = 10 }
  local b = w:rigid{ shape = "box", half = {0.3, 0.3, 0.3}, mass = 2, pos = {0, 0, 0} }
  local p = w:particle{ pos = {0.1, 0.05, 0}, mass = 1, radius = 0.05 }
  w:attach(p, b)
  for _ = 1, 30 do w:step() end
  -- with the contact, the particle is pushed out of the box while the attachment holds
  -- it in: the two fight and the pair moves off; without it nothing moves at all
  local x, y, z = w:position(p)
  expect.near(x, 0.1, 1e-12); expect.near(y, 0.05, 1e-12); expect.near(z, 0, 1e-12)
  local bx, by, bz = b:position()
  expect.near(bx, 0, 1e-12); expect.near(by, 0, 1e-12); expect.near(bz, 0, 1e-12)
  -- another body's particle is still pushed out of this one (made 0.25 m inside: at
  -- max_depenetration, 0.25 m/s, it is out after 1 s)
  local q = w:particle{ pos = {-0.1, 0, 0}, mass = 1, radius = 0.05 }
  for _ = 1, 75 do w:step() end
  expect.ge(b:distance(w:position(q)), 0.05 - 1e-6, "a free particle is pushed out of the box")
end)
