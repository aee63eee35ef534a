-- depenetration.lua: bodies made overlapping push apart gently.
--
-- A pair's overlap at the start of a substep is a position error, not a collision:
-- src/core/contact.c pushes it out at no more than max_depenetration (m/s, default
-- 0.25) and takes the speed that push implies out of the velocity again, so repairing
-- it adds no kinetic energy; approaching pairs are still stopped in full (contacts.lua).
-- Before this, a pair overlapping by depth left its substep at depth / h apart.
--
-- The scene: two stiff soft blocks (5^3 particles, spacing 0.1, radius 0.05) made with
-- their facing layers 0.05 apart, half inside each other's contact distance, in zero
-- gravity. Without the limit every overlapping pair would be 0.05 m apart after one
-- substep: 30 m/s, which the links spread over the blocks (measured: 4.5 m/s each,
-- 10 J each). With it the facing layers move apart at vmax; the blocks' links carry that
-- to the rest of each block and give back the small compression on the way (measured:
-- relative speed 1.2 vmax), so 2 vmax bounds the blocks' relative speed with margin,
-- and the kinetic energy stays below what 2 vmax apart would be for each block.

local function blocks(vmax, comp)
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = 10, iterations = 2, max_depenetration = vmax }
  local a = w:lattice{ min = {-0.4, -0.2, -0.2}, max = {0, 0.2, 0.2}, res = {5, 5, 5}, mass = 1, compliance = comp }
  local b = w:lattice{ min = {0.05, -0.2, -0.2}, max = {0.45, 0.2, 0.2}, res = {5, 5, 5}, mass = 1, compliance = comp }
  return w, a, b
end

local function com_vx(w, body)
  local s = 0
  for _, p in ipairs(body.particles) do s = s + w:velocity(p) end
  return s / #body.particles
end

local function kinetic(w, body)
  local e = 0
  for _, p in ipairs(body.particles) do
    local vx, vy, vz = w:velocity(p)
    e = e + 0.5 / #body.particles * (vx * vx + vy * vy + vz * vz) -- mass 1 over the particles
  end
  return e
end

local function gap(w, a, b) -- the closest pair across the blocks, over its contact distance
  local best = math.huge
  for _, p in ipairs(a.particles) do
    local px, py, pz = w:position(p)
    for _, q in ipairs(b.particles) do
      local qx, qy, qz = w:position(q)
      best = math.min(best, math.sqrt((px - qx) ^ 2 + (py - qy) ^ 2 + (pz - qz) ^ 2) / (w:radius(p) + w:radius(q)))
    end
  end
  return best
end

for _, case in ipairs{ { 0.25, 1e-5 }, { 0.1, 1e-5 }, { 0.25, 1e-3 } } do
  local vmax, comp = case[1], case[2]
  test(string.format("blocks made half inside each other separate at max_depenetration = %g (compliance %g)",
                     vmax, comp), function()
    local w, a, b = blocks(vmax, comp)
    expect.lt(gap(w, a, b), 0.51, "made overlapping")
    local px0, py0, pz0 = w:momentum()
    local rel, energy = 0, 0
    w:run{ seconds = 1, on_frame = function(w)
      rel = math.max(rel, com_vx(w, b) - com_vx(w, a))
      energy = math.max(energy, kinetic(w, a), kinetic(w, b))
      local px, py, pz = w:momentum()
      -- every correction is split by inverse mass: exact to round-off (1 kg blocks at
      -- a few m/s at most: 1e-12 is thousands of ulps)
      expect.near(px, px0, 1e-12, "momentum x")
      expect.near(py, py0, 1e-12, "momentum y")
      expect.near(pz, pz0, 1e-12, "momentum z")
    end }
    expect.ge(gap(w, a, b), 0.999, "apart after 1 s")
    expect.gt(com_vx(w, b) - com_vx(w, a), 0, "moving apart")
    expect.lt(rel, 2 * vmax, "relative speed of the blocks' centres below 2 max_depenetration")
    expect.lt(energy, 0.5 * (2 * vmax) ^ 2, "each block's kinetic energy below 1/2 m (2 vmax)^2")
  end)
end

test("head-on particles are still stopped in one substep whatever max_depenetration", function()
  -- the limit applies to overlap a pair already had, never to an approach
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = 1, max_depenetration = 0 }
  local a = w:particle{ pos = {-1, 0, 0}, vel = {3, 0, 0}, mass = 1, radius = 0.1 }
  local b = w:particle{ pos = {1, 0, 0}, vel = {-1, 0, 0}, mass = 2.5, radius = 0.15 }
  w:run{ frames = 60 }
  expect.near((w:velocity(a)), 0.5 / 3.5, 1e-12)
  expect.near((w:velocity(b)), 0.5 / 3.5, 1e-12)
  local ax = w:position(a)
  local bx = w:position(b)
  expect.near(bx - ax, 0.25, 1e-12, "in touch")
end)

test("max_depenetration: checked, and kept by a snapshot", function()
  expect.error(function() wobble.world{ max_depenetration = -1 } end, "max_depenetration")
  expect.error(function() wobble.world{ max_depenetration = math.huge } end, "max_depenetration")
  -- saved mid-separation and loaded, the world goes on exactly as the original (with
  -- the default limit instead the blocks would part faster)
  local w = blocks(0.1, 1e-5)
  w:run{ frames = 3 }
  expect.eq(w:save("depenetration.json"), true)
  local v = assert(wobble.load("depenetration.json"))
  w:run{ frames = 20 }
  v:run{ frames = 20 }
  expect.eq(v:hash(), w:hash())
end)
