-- contact_kinetic.lua: dynamic friction of particle and triangle contacts
-- against physics and against the collider contacts, whose rule it now follows.
--
-- The model (src/core/contact.c, tricontact.c): a pair sliding faster than one substep
-- of friction can stop gets no friction at position level; after v = (x - x_prev)/h the
-- velocity pass takes mu x (its normal impulse) off the relative tangential speed,
-- mu depth / h (depth: its normal correction, here the weight's g h^2), at most all of
-- it, split by inverse mass (barycentric weights for a triangle), as collide.c does for
-- a collider. So:
--  * a particle sliding at v0 on a flat surface loses mu g h per substep and stops after
--    v0^2 / (2 mu g). Velocity-level friction moves each substep at the speed before
--    its friction (symplectic Euler): the slide is longer by v0 h / 2 (1.7 mm here, 0.4%)
--    plus at most one substep's v h at the end: 1% covers both;
--  * it is the collider's rule, so a slide on a pinned cloth (triangle contacts) matches
--    the slide on a plane collider to round-off, and on a huge pinned particle (a pair)
--    the slide on a sphere collider. Friction at position level (before: the slip of
--    each substep undone by mu depth) slid shorter than the collider, by 3.3 mm (0.8%)
--    and 1.6 mm: it failed these checks;
--  * each correction is equal and opposite (mass-weighted), so two free bodies sliding
--    on each other keep their momentum to round-off and end at the common velocity.

local mu, g = 0.5, 9.81

-- the slide of a particle (radius 0.02, 0.1 kg) launched at v0 along x; returns the
-- distance it went and the frame its speed first read zero
local function slide(w, p, v0, frames)
  local x0 = w:position(p)
  local stopped
  w:set_velocity(p, v0, 0, 0)
  w:run{ frames = frames, on_frame = function(w, f)
    if not stopped and (w:velocity(p)) == 0 then stopped = f end
  end }
  return w:position(p) - x0, stopped
end

-- a wide pinned cloth (9 x 9 particles 0.5 m apart, radius 0.01) in y = 0: flat triangles
local function on_sheet(substeps)
  local w = wobble.world{ substeps = substeps }
  local c = w:cloth{ origin = {-2, 0, -2}, size = {4, 4}, res = {9, 9}, mass = 1, radius = 0.01, friction = mu }
  c:pin_where(function() return true end)
  local p = w:particle{ pos = {-1.03, 0.02, 0.07}, radius = 0.02, mass = 0.1, friction = mu }
  return w, p
end

local function on_plane(substeps)
  local w = wobble.world{ substeps = substeps }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = mu }
  local p = w:particle{ pos = {-1.03, 0.02, 0.07}, radius = 0.02, mass = 0.1 }
  return w, p
end

test("a particle sliding on a pinned sheet stops after v0^2 / (2 mu g), as on a plane collider", function()
  local v0 = 2
  local w, p = on_sheet(10)
  local d, stopped = slide(w, p, v0, 60)
  local theory = v0 ^ 2 / (2 * mu * g)
  expect.near(d, theory, 0.01 * theory, "slide length (0.408 m)")
  -- it loses mu g / 60 per frame: stopped in the frame where v0 / (mu g) = 0.41 s ends
  expect.eq(stopped, math.ceil(v0 / (mu * g) * 60), "the frame it stopped in")
  local _, y, z = w:position(p)
  expect.near(y, 0.02, 1e-12, "on the sheet at its radius")
  expect.near(z, 0.07, 1e-12, "straight on")
  local wc, pc = on_plane(10)
  local dc = slide(wc, pc, v0, 60)
  expect.near(d, dc, 1e-9 * dc, "the same slide as on a plane collider of the same friction")
end)

test("a particle sliding on a huge pinned particle slides as on a sphere collider", function()
  -- a pair contact: the pinned particle (R = 100 m, centre 100 m below) is locally a
  -- plane; the same sphere as a collider gives the collider's slide
  local R, v0 = 100, 1
  local w = wobble.world{}
  w:particle{ pos = {0, -R, 0}, radius = R, mass = 0, friction = mu }
  local p = w:particle{ pos = {0, 0.02, 0}, radius = 0.02, mass = 0.1, friction = mu }
  local d, stopped = slide(w, p, v0, 30)
  expect.gt(stopped or math.huge, 0, "stopped")
  local wc = wobble.world{}
  wc:collider{ shape = "sphere", center = {0, -R, 0}, radius = R, friction = mu }
  local pc = wc:particle{ pos = {0, 0.02, 0}, radius = 0.02, mass = 0.1 }
  local dc = slide(wc, pc, v0, 30)
  local theory = v0 ^ 2 / (2 * mu * g)
  expect.near(d, theory, 0.01 * theory, "slide length (0.102 m)")
  -- the slope under it (x / R, 1e-3 at the end) decides its last substeps, where the
  -- pair's friction at rest may hold part of a slip and the collider's holds all or
  -- nothing: 0.026 mm apart measured; 0.1 mm allowed (friction at position level: 1.6 mm)
  expect.near(d, dc, 1e-4, "the same slide as on a sphere collider")
end)

test("without dynamic friction a slide would not stop: one substep of friction is mu g h", function()
  -- the same launch on a frictionless sheet goes on at v0 (so the checks above measure
  -- the friction, not something else stopping it)
  local w = wobble.world{}
  local c = w:cloth{ origin = {-2, 0, -2}, size = {4, 4}, res = {9, 9}, mass = 1, radius = 0.01 }
  c:pin_where(function() return true end)
  local p = w:particle{ pos = {-1.03, 0.02, 0.07}, radius = 0.02, mass = 0.1 }
  local d = slide(w, p, 2, 30)
  expect.near(d, 1, 1e-9, "2 m/s for 0.5 s")
end)

test("two free bodies sliding on each other: momentum exact, they end at the common velocity", function()
  -- a slab (4 kg) on a frictionless floor, a block (1 kg) launched along it at 2 m/s:
  -- friction between them is all that acts along x
  local w = wobble.world{ substeps = 10 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0 }
  local slab = w:lattice{ min = {-1, 0.05, -0.5}, max = {1, 0.15, 0.5}, res = {21, 2, 11}, mass = 4,
                          compliance = 1e-6, friction = mu }
  local block = w:lattice{ min = {-0.7, 0.25, -0.1}, max = {-0.5, 0.45, 0.1}, res = {3, 3, 3}, mass = 1,
                           compliance = 1e-6, friction = mu }
  for _, q in ipairs(block.particles) do w:set_velocity(q, 2, 0, 0) end
  local px0 = w:momentum()
  expect.near(px0, 2, 1e-12)
  local worst = 0
  w:run{ frames = 90, on_frame = function(w)
    local px, _, pz = w:momentum()
    worst = math.max(worst, math.abs(px - px0), math.abs(pz))
  end }
  -- each friction change is m_i dv_i = -m_j dv_j: what is left is the rounding of the
  -- sums over 8e2 particles (an ulp of 1 m/s is 2e-16)
  expect.lt(worst, 1e-12, "momentum along the slab")
  local function vx(body)
    local s = 0
    for _, q in ipairs(body.particles) do s = s + w:velocity(q) end
    return s / #body.particles
  end
  -- stuck together: m_b v0 / (m_a + m_b) = 0.4 m/s (the slide took v0 / (mu g (1 + 1/4))
  -- = 0.33 s); both bodies at it to 1%
  expect.near(vx(block), 0.4, 0.004, "the block")
  expect.near(vx(slab), 0.4, 0.004, "the slab")
end)

test("a particle wedged at rest reads no speed (the velocity pass made a phantom one)", function()
  -- on the floor, under two pinned particles 30 degrees either side of the vertical that
  -- overlap it by 0.2 mm: every substep they push it down, the floor pushes it back up,
  -- and it never moves. The velocity pass took the speed of that repair (0.2 mm / h =
  -- 0.12 m/s) out of each pair whatever speed the pair had: along two normals at 60
  -- degrees that left 5.3 cm/s on a particle that stayed put. At most the pair's
  -- separating speed is taken out now
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  local r, a, d = 0.02, math.rad(30), 0.04 - 2e-4
  w:particle{ pos = {-d * math.sin(a), r + d * math.cos(a), 0}, radius = r, mass = 0 }
  w:particle{ pos = { d * math.sin(a), r + d * math.cos(a), 0}, radius = r, mass = 0 }
  local p = w:particle{ pos = {0, r, 0}, radius = r, mass = 0.1 }
  w:run{ frames = 10 }
  local x, y = w:position(p)
  w:run{ frames = 10 }
  local x1, y1 = w:position(p)
  expect.near(x1, x, 1e-12, "it stays put")
  expect.near(y1, y, 1e-12, "it stays put")
  local vx, vy, vz = w:velocity(p)
  expect.lt(math.sqrt(vx * vx + vy * vy + vz * vz), 1e-9, "its speed")
  expect.gt(w:stats().particle_contacts, 1, "wedged")
end)
