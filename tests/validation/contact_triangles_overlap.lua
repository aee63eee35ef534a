-- contact_triangles_overlap.lua: a particle made inside its radius of a triangle is pushed
-- out gently, as a pair made overlapping is (tests/validation/depenetration.lua).
--
-- src/core/tricontact.c follows contact.c's rule for old overlap: what a particle and a
-- triangle already overlapped by at a substep's start and were themselves left with (before
-- a frame's first substep: all of it) goes out at no more than max_depenetration (m/s,
-- default 0.25) x h per substep, and the speed that push implies is taken out of the
-- velocity again. Before this a particle made 1.5 cm deep in a sheet's contact distance
-- left the first substep at depth / h = 9 m/s (4 J out of nothing for 0.1 kg), while a
-- pair made as deep moved apart at 0.25 m/s.
--
-- The scenes have no gravity and nothing moving: every position change is the repair.

-- a coarse cloth (5 x 5 particles 0.5 m apart in y = 0), radius 0.02 for the particle;
-- the particle made at height y0 over a point inside a triangle
local function made_inside(y0, pinned, vmax)
  local w = wobble.world{ gravity = {0, 0, 0}, max_depenetration = vmax }
  local c = w:cloth{ origin = {-1, 0, -1}, size = {2, 2}, res = {5, 5}, mass = 1, radius = 0.02 }
  if pinned then c:pin_where(function() return true end) end
  local p = w:particle{ pos = {0.13, y0, 0.21}, radius = 0.02, mass = 0.1 }
  return w, p, c
end

local dt = 1 / 60

test("a particle made 1.5 cm inside a pinned sheet's reach moves out at max_depenetration, with no speed", function()
  local w, p = made_inside(0.005, true)
  local y = 0.005
  for f = 1, 6 do
    w:step()
    local _, ny = w:position(p)
    -- out by vmax dt a frame (1/240 m) until it is at its radius; round-off is 1e-12
    expect.near(ny, math.min(0.02, 0.005 + f * 0.25 * dt), 1e-12, "frame " .. f .. ": at most vmax dt further out")
    expect.ge(ny, y, "never back in")
    y = ny
    local vx, vy, vz = w:velocity(p)
    expect.lt(math.sqrt(vx * vx + vy * vy + vz * vz), 1e-9, "frame " .. f .. ": the push made no speed")
    expect.lt(w:energy(), 1e-15, "no kinetic energy")
  end
  expect.near(y, 0.02, 1e-12, "out at its radius")
end)

test("the same with max_depenetration = 1e3: out at once, still with no speed", function()
  local w, p = made_inside(0.005, true, 1e3)
  w:step()
  expect.near(select(2, w:position(p)), 0.02, 1e-12, "at its radius after a frame")
  local _, vy = w:velocity(p)
  expect.near(vy, 0, 1e-9, "no speed")
end)

test("made inside a free sheet: momentum stays zero and next to no kinetic energy is made", function()
  local w, p = made_inside(0.005, false)
  for _ = 1, 10 do w:step() end
  local px, py, pz = w:momentum()
  -- the corrections and the speed taken back carry no momentum (weights b_i, sum 1):
  -- round-off of 26 velocities
  expect.lt(math.abs(px) + math.abs(py) + math.abs(pz), 1e-12, "momentum")
  -- the particle and the sheet move apart at vmax; the sheet's links spread the corners'
  -- share and give back the dent it made (measured: 1.2e-4 J). The particle's energy at
  -- 2 vmax, 0.5 x 0.1 x 0.5^2 = 1.25e-2 J, bounds that with margin (without the rule:
  -- 3.9 J, the particle leaving at ~9 m/s)
  expect.lt(w:energy(), 0.5 * 0.1 * (2 * 0.25) ^ 2, "kinetic energy below the particle's at 2 vmax")
  local _, vy = w:velocity(p)
  expect.lt(math.abs(vy), 2 * 0.25, "the particle slower than 2 vmax")
end)
