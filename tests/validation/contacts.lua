-- contacts.lua: particle-particle contacts against physics.
--
-- The contact model (src/core/contact.c): every substep each candidate pair with
-- |x_i - x_j| < r_i + r_j is pushed apart along its line to exactly r_i + r_j, the
-- correction split by inverse mass (XPBD with compliance 0); after the velocity update
-- the pair's approach speed is removed, split the same way. So:
--  * momentum: each correction moves m_i dx_i + m_j dx_j = 0 (w_i m_i = 1), exact up to
--    the rounding of 1/m and of the sums: 1e-12 relative is ~1e4 ulps of margin;
--  * a head-on pair ends a substep exactly in touch (to round-off) and leaves it with
--    no relative normal speed: perfectly inelastic, both at the centre-of-mass velocity;
--  * overlap is left only where other constraints (links, colliders) moved a particle
--    after the contact pass of the substep; the tolerances below say how much.

local function head_on(contacts)
  local w = wobble.world{ gravity = {0, 0, 0}, contacts = contacts }
  local a = w:particle{ pos = {-1, 0, 0}, vel = {3, 0.5, 0}, mass = 1, radius = 0.1 }
  local b = w:particle{ pos = {1, 0, 0}, vel = {-1, 0.5, 0}, mass = 2.5, radius = 0.15 }
  return w, a, b
end

local function dist(w, a, b)
  local ax, ay, az = w:position(a)
  local bx, by, bz = w:position(b)
  return math.sqrt((ax - bx) ^ 2 + (ay - by) ^ 2 + (az - bz) ^ 2)
end

test("head-on: no overlap, momentum exact, perfectly inelastic", function()
  local w, a, b = head_on()
  local px0, py0 = w:momentum()
  local min_d = math.huge
  w:run{ frames = 60, on_frame = function(w)
    min_d = math.min(min_d, dist(w, a, b))
    local px, py, pz = w:momentum()
    expect.near(px, px0, 1e-12 * math.abs(px0), "momentum x")
    expect.near(py, py0, 1e-12 * math.abs(py0), "momentum y")
    expect.near(pz, 0, 1e-15, "momentum z")
  end }
  -- pushed to exactly r_a + r_b each substep; nothing else moves them
  expect.ge(min_d, 0.25 - 1e-12, "never closer than r_a + r_b")
  -- stuck together at the centre-of-mass velocity (3 - 2.5) / 3.5 along x
  local vax, vay = w:velocity(a)
  local vbx, vby = w:velocity(b)
  expect.near(vax, 0.5 / 3.5, 1e-12)
  expect.near(vbx, 0.5 / 3.5, 1e-12)
  expect.near(vay, 0.5, 1e-12)
  expect.near(vby, 0.5, 1e-12)
  expect.near(dist(w, a, b), 0.25, 1e-12, "in touch")
end)

test("head-on, one substep per frame: inelastic in the substep they meet", function()
  -- the velocity pass removes the approach speed at once (without it the pair would
  -- overlap again in the next substep and be stopped only then)
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = 1 }
  local a = w:particle{ pos = {-1, 0, 0}, vel = {3, 0, 0}, mass = 1, radius = 0.1 }
  local b = w:particle{ pos = {1, 0, 0}, vel = {-1, 0, 0}, mass = 2.5, radius = 0.15 }
  local met
  w:run{ frames = 60, on_frame = function(w, f)
    if not met and dist(w, a, b) < 0.25 + 1e-9 then
      met = f
      expect.near((w:velocity(a)), 0.5 / 3.5, 1e-12, "a, frame " .. f)
      expect.near((w:velocity(b)), 0.5 / 3.5, 1e-12, "b, frame " .. f)
      expect.gt(w:stats().particle_contacts, 0)
    end
  end }
  expect.truthy(met, "they met")
end)

test("contacts = false: the same pair passes through (so the test above tests something)", function()
  local w, a, b = head_on(false)
  w:run{ frames = 60 }
  local ax = w:position(a)
  local bx = w:position(b)
  expect.gt(ax, bx, "a ended beyond b")
  expect.eq(w:stats().particle_contacts, 0)
end)

-- two soft blocks, one on the other, on the ground
local function stack(contacts)
  local w = wobble.world{ substeps = 10, iterations = 2, contacts = contacts }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
  -- friction between the blocks: without it the top one never stops rolling about on
  -- the bumps of the lower one's particles (nothing dissipates tangential motion)
  local lo = w:lattice{ min = {-0.3, 0.1, -0.3}, max = {0.3, 0.7, 0.3}, res = {4, 4, 4}, mass = 2, compliance = 1e-5,
                        friction = 0.5 }
  local hi = w:lattice{ min = {-0.25, 0.9, -0.25}, max = {0.25, 1.4, 0.25}, res = {4, 4, 4}, mass = 1, compliance = 1e-5,
                        friction = 0.5 }
  return w, lo, hi
end

local function centre(w, body)
  local sx, sy, sz = 0, 0, 0
  for _, p in ipairs(body.particles) do
    local x, y, z = w:position(p)
    sx, sy, sz = sx + x, sy + y, sz + z
  end
  local n = #body.particles
  return sx / n, sy / n, sz / n
end

local function extent(w, body)
  local lo, hi = math.huge, -math.huge
  for _, p in ipairs(body.particles) do
    local _, y = w:position(p)
    lo, hi = math.min(lo, y), math.max(hi, y)
  end
  return lo, hi
end

-- the closest pair of particles of two bodies, relative to its contact distance
local function closest(w, A, B)
  local best = math.huge
  for _, p in ipairs(A.particles) do
    local px, py, pz = w:position(p)
    for _, q in ipairs(B.particles) do
      local qx, qy, qz = w:position(q)
      local d = math.sqrt((px - qx) ^ 2 + (py - qy) ^ 2 + (pz - qz) ^ 2)
      best = math.min(best, d / (w:radius(p) + w:radius(q)))
    end
  end
  return best
end

test("two stacked blocks settle and stay apart: no interpenetration, no creep", function()
  local w, lo, hi = stack()
  expect.near(w:radius(lo.particles[1]), 0.1, 1e-12, "default radius: half the spacing (0.6 / 3 / 2)")
  expect.truthy(lo.group ~= hi.group and lo.group > 0 and hi.group > 0, "a group each")
  w:run{ seconds = 2 }
  local _, top_lo = extent(w, lo)
  local bot_hi = extent(w, hi)
  -- resting: the top block's bottom layer (r = 0.083) on the lower block's top layer
  -- (r = 0.1, spacing 0.2): a sphere in the hollow of four sits sqrt(0.183^2 - 0.141^2)
  -- = 0.116 above them, on a ridge between two 0.154, on top of one 0.183
  expect.gt(bot_hi - top_lo, 0.11, "the top block rests on the lower one")
  -- the contact pass ends each substep with every pair at >= r_i + r_j; the links and
  -- the floor then move particles by the load's g h^2 per substep: 3% is ample
  expect.ge(closest(w, lo, hi), 0.97, "no pair closer than 97% of its contact distance")
  local x0, y0, z0 = centre(w, hi)
  w:run{ seconds = 3 }
  local x1, y1, z1 = centre(w, hi)
  -- no creep: measured 0.1 mm sideways and nothing downwards over these 3 s; 1 mm is
  -- far below the 2 cm a frictionless top block wanders on the bumps
  expect.near(y1, y0, 1e-3, "the top block's height after 3 s more")
  expect.near(x1, x0, 1e-3, "no sideways creep (x)")
  expect.near(z1, z0, 1e-3, "no sideways creep (z)")
  expect.ge(closest(w, lo, hi), 0.97)
  expect.gt(w:stats().particle_contacts, 0, "in contact")
end)

test("stacked blocks without contacts sink into each other", function()
  local w, lo, hi = stack(false)
  w:run{ seconds = 2 }
  expect.lt(closest(w, lo, hi), 0.5)
end)

-- a block on a fixed slab, gravity tilted by theta (the same as tilting the slab):
-- Coulomb says it sticks while tan(theta) < mu and slides above
local function incline(theta, mu)
  local g = 9.81
  local w = wobble.world{ gravity = {g * math.sin(theta), -g * math.cos(theta), 0}, substeps = 20 }
  -- a dense slab of large, overlapping spheres: a nearly flat surface (bumps of
  -- spacing^2 / (8 r) = 0.6 mm, slopes below asin(0.015 / 0.2) = 4.3 deg at worst, and
  -- averaged over the block's particles, which sit at other phases of the bumps)
  local slab = w:lattice{ min = {-1, 0, -0.4}, max = {2, 0.1, 0.4}, res = {101, 2, 28}, radius = 0.1,
                          friction = mu }
  slab:pin_all()
  local block = w:lattice{ min = {-0.7, 0.3, -0.2}, max = {-0.3, 0.7, 0.2}, res = {3, 3, 3}, radius = 0.1,
                           mass = 1, compliance = 1e-6, friction = mu }
  local function x() local s = 0 for _, p in ipairs(block.particles) do s = s + w:position(p) end return s / #block.particles end
  w:run{ seconds = 0.5 } -- lands and settles
  local x0 = x()
  w:run{ seconds = 1 }
  return x() - x0
end

test("friction between bodies: a block sticks below tan(theta) = mu and slides above", function()
  local mu = 0.5
  local crit = math.atan(mu)
  -- 5% either side of the critical angle (measured: it holds at 0.98 theta_c and slides
  -- at 1.00, 4.6 cm in 1 s; the slab's bumps shift the threshold by a few percent)
  local stick = incline(crit * 0.95, mu)
  local slide = incline(crit * 1.05, mu)
  expect.lt(math.abs(stick), 0.001, "at 0.95 theta_c it moves less than 1 mm in 1 s")
  -- Coulomb: a = g (sin - mu cos) = 0.25 m/s^2 at 1.05 theta_c: 0.13 m in 1 s from rest,
  -- 0.25 m from t = 0.5 to 1.5 s sliding from the start (measured 0.27 m)
  expect.gt(slide, 0.06, "at 1.05 theta_c it slides")
  local free = incline(crit * 0.95, 0)
  expect.gt(free, 0.5, "without friction it slides at 0.95 theta_c too")
end)

-- a cloth laid half flat on the floor and half standing up, the standing half tipped over
-- (1 rad/s about the fold) onto the flat one: it lands on it. (A cloth stood on its edge
-- and pushed in a wave crumpled only by the lean of a creation-order colouring: with
-- mirror images coloured alike it no longer came down on itself.)
local function fold(self_collide)
  local w = wobble.world{ substeps = 20, iterations = 2 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
  local n = 16
  local cloth = w:cloth{ origin = {-0.5, 0, -0.5}, size = {1, 1}, res = {n, n}, mass = 0.2, compliance = 1e-6,
                         self_collide = self_collide, friction = 0.2 }
  local r = w:radius(cloth.particles[1])
  local spacing = 1 / (n - 1)
  local hinge = -0.5 + (n // 2) * spacing -- a row of particles: the fold lays rows on rows
  for _, p in ipairs(cloth.particles) do
    local x, _, z = w:position(p)
    if z <= hinge + 1e-9 then
      w:set_position(p, x, r, z)
    else
      w:set_position(p, x, r + z - hinge, hinge)
      w:set_velocity(p, 0, 0, -(z - hinge))
    end
  end
  w:run{ seconds = 2 }
  -- the rule's pairs: not joined by a link and at least 2 r apart as built
  local linked = {}
  for _, c in ipairs(w:distances()) do
    local a, b = c:particles()
    linked[a * 100000 + b], linked[b * 100000 + a] = true, true
  end
  local worst = math.huge
  for i, p in ipairs(cloth.particles) do
    local pi, pj = (i - 1) % n, (i - 1) // n
    local px, py, pz = w:position(p)
    for k = i + 1, #cloth.particles do
      local q = cloth.particles[k]
      local qi, qj = (k - 1) % n, (k - 1) // n
      local rest = math.sqrt((pi - qi) ^ 2 + (pj - qj) ^ 2) * spacing
      if not linked[p * 100000 + q] and rest >= 2 * r then
        local qx, qy, qz = w:position(q)
        worst = math.min(worst, math.sqrt((px - qx) ^ 2 + (py - qy) ^ 2 + (pz - qz) ^ 2) / (2 * r))
      end
    end
  end
  local _, _, _, _, maxy = w:bounds()
  return worst, maxy, r
end

test("self-collision: a cloth folded onto itself keeps its non-neighbours a contact distance apart", function()
  local worst, maxy, r = fold(true)
  -- the floor and the links move particles after the contact pass of a substep: 10% of
  -- the contact distance covers that (measured: 0.9997)
  expect.ge(worst, 0.9, "closest non-neighbour pair / 2 r")
  expect.lt(worst, 1.1, "the halves touch: the self-collision was at work")
  expect.gt(maxy, 2 * r, "one half lies on the other")
  local worst_off = fold(false)
  expect.lt(worst_off, 0.5, "without self_collide the cloth passes through itself")
end)

test("determinism with contacts: the same hash with 1 and 2 threads", function()
  local function pile(threads)
    local w = wobble.world{ threads = threads, substeps = 8 }
    w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.4 }
    for i = 0, 7 do
      local x, z = (i % 3) * 0.25 - 0.25, (i // 3) * 0.25 - 0.25
      w:lattice{ min = {x, 0.3 + 0.3 * i, z}, max = {x + 0.3, 0.6 + 0.3 * i, z + 0.3}, res = {3, 3, 3},
                 compliance = 1e-5, friction = 0.3 }
    end
    for i = 1, 20 do w:particle{ pos = {i * 0.03 - 0.3, 3, 0}, radius = 0.04 } end
    -- contacts over the run (the last substep alone may have none: the pile scatters)
    local contacts = 0
    w:run{ frames = 90, on_frame = function(w) contacts = contacts + w:stats().particle_contacts end }
    return w:hash(), contacts
  end
  local h1, n1 = pile(1)
  local h2 = pile(2)
  expect.gt(n1, 100, "the pile is in contact")
  expect.eq(h1, h2)
end)

test("determinism with contacts, a pile big enough for the parallel broad phase: 1 and 2 threads", function()
  -- 27 blocks (1728 particles, past the 1024 from which the broad phase runs on every
  -- thread) in a heap, squeezed by four walls so that they keep touching
  local function heap(threads)
    local w = wobble.world{ threads = threads, substeps = 3 }
    w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.4 }
    for _, n in ipairs{ {1, 0, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 0, -1} } do
      w:collider{ shape = "plane", normal = n, offset = -0.8, friction = 0.2 }
    end
    for k = 0, 26 do
      local i, j, l = k % 3, (k // 3) % 3, k // 9
      local x, y, z = -0.8 + 0.55 * i + 0.02 * l, 0.1 + 0.55 * l, -0.8 + 0.55 * j
      w:lattice{ min = {x, y, z}, max = {x + 0.5, y + 0.5, z + 0.5}, res = {4, 4, 4}, compliance = 1e-5,
                 friction = 0.3 }
    end
    local contacts = 0
    for _ = 1, 12 do
      w:step()
      contacts = contacts + w:stats().particle_contacts
    end
    return w:hash(), contacts
  end
  local h1, n1 = heap(1)
  expect.gt(n1, 200, "the heap is in contact")
  expect.eq(heap(2), h1)
end)
