-- contact_energy.lua: bodies made overlapping part without gaining energy from their
-- contacts (src/core/contact.c, src/core/tricontact.c).
--
-- Overlap a pair already had is a position error: each pair pushes its overlap out at
-- no more than max_depenetration (vmax, 0.25 m/s) and that push is no speed. What
-- repairing it may add, at most: the bodies lifted by up to the deepest overlap d
-- (M g d), and speed from the parting itself: a pair parts at vmax, a body between two
-- others is pushed from both sides, and its links carry the push of its surface to the
-- rest of it with some overshoot (depenetration.lua measured 1.2 vmax for one pair);
-- 4 vmax bounds every body here (1/2 M (4 vmax)^2). The measure, every frame from the
-- start: the mechanical energy K + m g y (the elastic energy, >= 0, left out) never
-- exceeds the energy they were made with (at rest: m g y) by more than that bound.
-- Measured with the fix: 4.3 J of the 11.8 J allowed for the eight blocks (1.5 J since
-- bodies made deep inside each other part as wholes, contact.c), 0.13 J of
-- 4.4 J for the squeezed block, 0.24 J of 1 J for the row of particles. Before it,
-- the blocks gained 150 J and 13 J (a triangle contact repaired all of its overlap in
-- one substep, as speed; a contact counted the links' pull-back as old overlap and
-- took its speed away) and flew metres apart. Then the bodies lie still in a bounded
-- region.

local g, vmax = 9.81, 0.25

local function floor(w) w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.4 } end

local function mechanical(w)
  local k = w:energy()
  local pg = 0
  for p = 1, w:particle_count() do
    local _, y = w:position(p)
    pg = pg + w:mass(p) * g * y
  end
  return k + pg
end

-- the deepest overlap left between particles that collide (of different bodies, or loose),
-- as a fraction of their contact distance r_i + r_j
local function deepest(w)
  local worst, n = 0, w:particle_count()
  for p = 1, n do
    local px, py, pz = w:position(p)
    local gp = w:group(p)
    for q = p + 1, n do
      local gq = w:group(q)
      if gp == 0 or gq == 0 or gp ~= gq then
        local qx, qy, qz = w:position(q)
        local rr = w:radius(p) + w:radius(q)
        local ov = 1 - math.sqrt((px - qx) ^ 2 + (py - qy) ^ 2 + (pz - qz) ^ 2) / rr
        if ov > worst then worst = ov end
      end
    end
  end
  return worst
end

-- d: the deepest overlap the bodies were made with; box: where they must come to rest
local function check(w, d, frames, box)
  local mass = 0
  for p = 1, w:particle_count() do mass = mass + w:mass(p) end
  local e0 = mechanical(w)
  expect.near(e0, (w:energy()) + select(2, w:energy()), 1e-9 * e0, "made at rest, unstrained")
  local allowed = mass * g * d + 0.5 * mass * (4 * vmax) ^ 2
  local worst, at = -math.huge, 0
  for f = 1, frames do
    w:step()
    local gain = mechanical(w) - e0
    if gain > worst then worst, at = gain, f end
  end
  expect.lt(worst, allowed, string.format("energy gained (worst at frame %d)", at))
  local x0, _, z0, x1, y1, z1 = w:bounds()
  expect.gt(x0, -box, "bounds x min"); expect.lt(x1, box, "bounds x max")
  expect.gt(z0, -box, "bounds z min"); expect.lt(z1, box, "bounds z max")
  expect.lt(y1, box, "bounds y max")
  expect.lt(w:energy(), 1e-3 * mass, "at rest: kinetic energy below 1 mJ per kg")
  -- and they have parted: what a resting contact keeps is the solver's residual, about
  -- g h^2 a layer (0.04 mm at 8 substeps), far below 5% of a contact distance (2 mm for
  -- the particles, 7.5 mm for the blocks); made, they overlapped by 50-67%
  expect.lt(deepest(w), 0.05, "parted: no colliding pair overlaps by 5% of its contact distance")
end

test("eight blocks made interleaved (the contacts.lua pile) part and settle without gaining energy", function()
  -- 3x3x3 blocks (1 kg, 0.3 m, contact distance 0.15 m) 0.25 m apart in x and z, each
  -- one's bottom layer in the plane of the top layer of the one below: the particles
  -- of neighbours 0.05 m apart, overlapping by d = 0.1 m. A 2.7 m tower that topples:
  -- it spreads over about its height, and a block thrown off it tumbles on along the
  -- floor (with dynamic contact friction at velocity level one went 5.0 m, at 2 m/s):
  -- 7 m is where it must have stopped, far short of where blocks gaining energy fly
  -- (which block is thrown, and how far, changes with any change to the parting: 5.0 m,
  -- then 6.3 m once the blocks parted as wholes, with less energy gained)
  local w = wobble.world{ substeps = 8 }
  floor(w)
  for i = 0, 7 do
    local x, z = (i % 3) * 0.25 - 0.25, (i // 3) * 0.25 - 0.25
    w:lattice{ min = {x, 0.3 + 0.3 * i, z}, max = {x + 0.3, 0.6 + 0.3 * i, z + 0.3}, res = {3, 3, 3},
               compliance = 1e-5, friction = 0.3 }
  end
  check(w, 0.1, 300, 7)
end)

test("a block made squeezed between two others parts from them without gaining energy", function()
  -- three 3x3x3 blocks in a row, the facing layers 0.05 m apart: d = 0.1 m
  local w = wobble.world{ substeps = 8 }
  floor(w)
  for i = -1, 1 do
    local x = i * 0.35 - 0.15
    w:lattice{ min = {x, 0.1, -0.15}, max = {x + 0.3, 0.4, 0.15}, res = {3, 3, 3}, compliance = 1e-5, friction = 0.3 }
  end
  check(w, 0.1, 300, 1.5)
end)

test("a row of loose particles made overlapping spreads on the floor without gaining energy", function()
  -- 20 particles (50 g, radius 4 cm) 3 cm apart, every other one 2 cm higher: each
  -- overlaps its nearest neighbours by d < 0.05 m
  local w = wobble.world{ substeps = 8 }
  floor(w)
  for i = 1, 20 do
    w:particle{ pos = {i * 0.03 - 0.3, 0.04 + (i % 2) * 0.02, 0}, radius = 0.04, mass = 0.05, friction = 0.3 }
  end
  check(w, 0.05, 180, 1)
end)
