-- attach_grab.lua: grabs and attachments against physics.
--
-- Both are XPBD constraints C = x - target with a vector multiplier: compliance 0 puts
-- the particle on its target at the end of every substep (to round-off), a compliant one
-- is a zero-length spring of stiffness 1/alpha, and force() = lambda/h^2 is the force on
-- the particle. At rest in XPBD (see xpbd_compliance.lua) the prediction adds g h^2 of
-- offset each substep and the update must remove it: dlambda = -(C~)/(w + alpha~) gives
-- an offset of exactly m g alpha and lambda = -m g h^2, whatever h.

local g = 9.81

-- a chain of n particles of mass m, d apart, hanging from a grab on its top particle
local function chain(n, m, d, substeps)
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = substeps or 20 }
  local ids = {}
  for i = 0, n - 1 do ids[#ids + 1] = w:particle{ pos = {0, 2 - d * i, 0}, mass = m } end
  -- link damping settles the chain's bounce (it vanishes at rest: no force then)
  for i = 1, n - 1 do w:distance(ids[i], ids[i + 1], { damping = 0.5 }) end
  return w, ids
end

test("a grab holds a hanging chain at its target and carries its whole weight", function()
  local n, m = 10, 0.1
  local w, ids = chain(n, m, 0.1)
  local gr = w:grab(ids[1], {0, 2, 0})
  w:run{ seconds = 4 }
  -- compliance 0: on the target at every substep's end; round-off of coordinates ~1
  local x, y, z = w:position(ids[1])
  expect.near(x, 0, 1e-12, "grabbed particle x")
  expect.near(y, 2, 1e-12, "grabbed particle y")
  expect.near(z, 0, 1e-12, "grabbed particle z")
  -- the grab carries the weight of everything below it and of its own particle: n m g.
  -- At rest exactly (the links' damping vanishes then); 1 % leaves room for what is
  -- left of the chain's swing after 4 s of link damping
  local f, fx, fy, fz = gr:force()
  expect.rel(f, n * m * g, 0.01, "g:force() = the chain's weight")
  expect.rel(fy, n * m * g, 0.01, "the force on the particle points up")
  expect.near(fx, 0, 1e-6, "no sideways force")
  expect.near(fz, 0, 1e-6, "no sideways force")
  -- the bottom still hangs below (the grab does not pull the chain up)
  expect.lt(select(2, w:position(ids[n])), 1.2, "the chain hangs")
end)

test("after g:release() the particle falls freely: v = g t exactly", function()
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  local p = w:particle{ pos = {0, 1, 0}, mass = 2 }
  local gr = w:grab(p, {0, 1, 0})
  w:run{ frames = 30 }
  local _, vy = w:velocity(p)
  expect.near(vy, 0, 1e-12, "held at rest")
  expect.near(select(2, w:position(p)), 1, 1e-12, "held at its target")
  gr:release()
  expect.falsy(gr:valid(), "released: no longer valid")
  expect.error(function() gr:force() end, "grab was released")
  expect.error(function() gr:move(0, 0, 0) end, "grab was released")
  local frames = 45
  w:run{ frames = frames }
  local t = frames / 60
  -- symplectic Euler gives the exact velocity of a free fall: v = g n h; round-off only
  _, vy = w:velocity(p)
  expect.rel(vy, -g * t, 1e-12, "v = g t after the release")
  -- position: x = x0 - g t^2/2 - g t h/2 (the integrator's first-order offset, h = dt/substeps)
  local h = 1 / 600
  expect.rel(1 - select(2, w:position(p)), g * t * t / 2 + g * t * h / 2, 1e-9, "fallen distance")
end)

test("a compliant grab stretches by m g alpha and reads back m g; its energy is C^2/(2 alpha)", function()
  local m, alpha, damping, seconds = 2, 1e-3, 2, 10
  local w = wobble.world{ gravity = {0, -g, 0}, damping = damping }
  local p = w:particle{ pos = {0, 0, 0}, mass = m }
  local gr = w:grab(p, {0, 0, 0}, { compliance = alpha })
  w:run{ seconds = seconds }
  -- the spring's swing (amplitude m g alpha at first) decays at least as exp(-d t / 2)
  -- under the world's velocity damping d (drag on the velocity only: no force at rest)
  local tol = 2 * m * g * alpha * math.exp(-damping * seconds / 2) + 1e-12
  local stretch = -select(2, w:position(p))
  expect.near(stretch, m * g * alpha, tol, "stretch = m g alpha")
  expect.near(gr:force(), m * g, tol / alpha, "force = m g")
  -- w:energy(): potential = gravity (m g y) + the grab's C^2/(2 alpha)
  local _, pe = w:energy()
  local elastic = pe + m * g * stretch  -- gravity: m g y, y = -stretch
  expect.near(elastic, stretch * stretch / (2 * alpha), 1e-12, "elastic energy of the grab")
  expect.rel(elastic, (m * g) ^ 2 * alpha / 2, 1e-3, "= (m g)^2 alpha / 2")
end)

test("g:move sweeps the target over the next step and the particle ends on it", function()
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = 10 }
  local p = w:particle{ pos = {0, 0, 0}, mass = 1 }
  local gr = w:grab(p, {0, 0, 0})
  gr:move(0.6, 0, 0)
  w:step()
  expect.near(w:position(p), 0.6, 1e-15, "on the moved target at the frame's end")
  -- swept over the frame, not jumped in one substep: the speed is 0.6 m / dt
  expect.rel(w:velocity(p), 0.6 * 60, 1e-9, "velocity = move / dt")
  expect.eq({ gr:target() }, { 0.6, 0, 0 })
end)

-- the rope's bottom end rises as the turning drum winds the rope on: by the radius the
-- rope's axis runs at (drum radius + particle radius) times the angle turned
test("a rope attached to a spinning capsule winds on it: rise = (R + r) x angle", function()
  local R, om, T = 0.2, 1.0, 3.0
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 20 }
  local drum = w:collider{ shape = "capsule", a = {0, 0, -0.3}, b = {0, 0, 0.3}, radius = R }
  local rope = w:rope{ from = {R + 0.02, 0, 0}, to = {R + 0.02, -2, 0}, segments = 40, mass = 1 }
  local r = w:radius(rope.particles[1])
  local a = w:attach(rope.particles[1], drum)
  local bottom = rope.particles[#rope.particles]
  w:run{ seconds = 1 }
  local y0 = select(2, w:position(bottom))
  drum:set_angular_velocity(0, 0, om)
  w:run{ seconds = T }
  local rise = select(2, w:position(bottom)) - y0
  -- the wound links are chords of the circle (0.05 m on 0.225 m: 0.2 % short of the arc)
  -- and the links stretch a little under the rope's weight (compliance 0 with 20
  -- substeps and one iteration: well under 1 %): 2 %
  expect.rel(rise, (R + r) * om * T, 0.02, "rise of the rope's end")
  -- the attached end rides its point on the drum exactly (it is inside the particle
  -- radius of the drum's surface, yet the drum does not push it off: no contact there)
  local ex, ey, ez = a:point()
  local x, y, z = w:position(rope.particles[1])
  expect.near(x, ex, 1e-12, "attached end on its point")
  expect.near(y, ey, 1e-12, "attached end on its point")
  expect.near(z, ez, 1e-12, "attached end on its point")
  -- the point turned with the drum: angle om T from where it started (+x)
  expect.near(math.atan(ey, ex), om * T - 2 * math.pi * math.floor((om * T + math.pi) / (2 * math.pi)), 1e-9,
              "the point turned with the drum")
end)

test("an attached particle inside its collider is not pushed out (no contact with its own collider)", function()
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  local ball = w:collider{ shape = "sphere", center = {0, 0, 0}, radius = 0.5 }
  local p = w:particle{ pos = {0.3, 0, 0}, mass = 1, radius = 0.05 }  -- inside the sphere
  local q = w:particle{ pos = {0.6, 0.5, 0}, mass = 1, radius = 0.05 }  -- a free one, for contrast
  w:attach(p, ball)
  ball:set_velocity(0, 0.3, 0)
  w:run{ frames = 30 }
  local x, y = w:position(p)
  expect.near(x, 0.3, 1e-12, "stays at its point inside")
  expect.near(y, 0.3 * 30 / 60, 1e-12, "rides the collider")
  -- other particles still collide with it
  local qx, qy = w:position(q)
  expect.ge(math.sqrt(qx * qx + (qy - 0.15) ^ 2), 0.55 - 1e-9, "a free particle is kept out")
end)

test("an attached particle rides a translating, turning box exactly", function()
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  local box = w:collider{ shape = "box", center = {1, 0, 0}, half = {0.2, 0.2, 0.2} }
  local p = w:particle{ pos = {1, 0.25, 0}, mass = 1, radius = 0.05 }  -- on the box's top face
  local a = w:attach(p, box)
  local v = {0.8, -0.3, 0.5}
  box:set_velocity(v[1], v[2], v[3])
  local frames = 90
  w:run{ frames = frames }
  local t = frames / 60
  local x, y, z = w:position(p)
  -- gravity pulls, but the attachment sets it on its point at every substep's end
  expect.near(x, 1 + v[1] * t, 1e-12, "x = x0 + v t")
  expect.near(y, 0.25 + v[2] * t, 1e-12, "y = y0 + v t")
  expect.near(z, v[3] * t, 1e-12, "z = z0 + v t")
  local vx, vy, vz = w:velocity(p)
  expect.near(vx, v[1], 1e-9, "moves with the box")
  expect.near(vy, v[2], 1e-9, "moves with the box")
  expect.near(vz, v[3], 1e-9, "moves with the box")
  -- the force holding it: its weight, m g up (the box moves at a constant velocity)
  local f, _, fy = a:force()
  expect.rel(f, g, 1e-9, "a:force() = m g")
  expect.rel(fy, g, 1e-9, "upwards")
  -- turning: a quarter turn about y carries the point from +y... to where the pose puts it
  box:set_velocity(0, 0, 0)
  box:set_angular_velocity(0, 0, math.pi / 2)  -- a quarter turn per second about z
  w:run{ seconds = 1 }
  local bx, by = box:position()
  x, y = w:position(p)
  expect.near(x - bx, -0.25, 1e-9, "a quarter turn about z: +y goes to -x")
  expect.near(y - by, 0, 1e-9, "a quarter turn about z")
end)

test("removing an attachment or its collider lets the particle go", function()
  local w = wobble.world{ gravity = {0, -g, 0} }
  local c1 = w:collider{ shape = "sphere", center = {0, 0, 0}, radius = 0.1 }
  local c2 = w:collider{ shape = "sphere", center = {5, 0, 0}, radius = 0.1 }
  local p = w:particle{ pos = {0, 1, 0} }
  local q = w:particle{ pos = {5, 1, 0} }
  local a1, a2 = w:attach(p, c1), w:attach(q, c2)
  w:run{ frames = 10 }
  expect.eq(w:stats().attachments, 2)
  expect.near(select(2, w:position(p)), 1, 1e-12, "held")
  a1:remove()
  c2:remove()
  expect.falsy(a1:valid(), "removed")
  expect.falsy(a2:valid(), "its collider removed")
  expect.error(function() a1:force() end, "attachment was removed")
  expect.eq(w:stats().attachments, 0)
  w:run{ frames = 30 }
  expect.lt(select(2, w:position(p)), 0.9, "falls once its attachment is removed")
  expect.lt(select(2, w:position(q)), 0.9, "falls once its collider is removed")
end)
