-- Free flight: a w:rope and a w:lattice thrown with gravity on, no collider. Internal
-- forces cannot move the centre of mass, so it follows the parabola
-- x = x0 + vx t, y = y0 + vy t - g t^2 / 2 while airborne; horizontal momentum is kept.
-- The integrator is symplectic Euler per substep (v += h g, then x += h v), whose exact
-- discrete solution is y0 + vy t - g t^2 / 2 - g h t / 2: tolerance g h t / 2 + 1e-9,
-- the first-order offset (8 mm after 1 s at h = 1/600 s).
local g = 9.81
local V = { 3, 5, 1 }

local function com(w, b)
  local sx, sy, sz, m = 0, 0, 0, 0
  for _, p in ipairs(b.particles) do
    local x, y, z = w:position(p)
    local mp = w:mass(p)
    sx, sy, sz, m = sx + mp * x, sy + mp * y, sz + mp * z, m + mp
  end
  return sx / m, sy / m, sz / m
end

local function fly(w, b, label)
  for _, p in ipairs(b.particles) do w:set_velocity(p, V[1], V[2], V[3]) end
  local x0, y0, z0 = com(w, b)
  local h = w:dt() / w:substeps()
  local px0 = w:momentum()
  local worst_x, worst_y, worst_z, tol_end = 0, -math.huge, 0, 0
  w:run{ seconds = 1, on_frame = function(w, f, t)
    local x, y, z = com(w, b)
    local tol = g * h * t / 2 + 1e-9
    worst_x = math.max(worst_x, math.abs(x - (x0 + V[1] * t)))
    worst_z = math.max(worst_z, math.abs(z - (z0 + V[3] * t)))
    local ey = math.abs(y - (y0 + V[2] * t - g * t * t / 2))
    worst_y = math.max(worst_y, ey - tol)
    tol_end = tol
  end }
  local px1 = w:momentum()
  print(string.format("%s: worst |x - x(t)| %.2e, |z - z(t)| %.2e, y error beyond the O(h) offset %.2e (offset at 1 s "
    .. "%.4f); px %.6f -> %.6f; max strain %.4f", label, worst_x, worst_z, worst_y, tol_end, px0, px1, w:max_strain()))
  expect.lt(worst_x, 1e-9, "x follows x0 + vx t")
  expect.lt(worst_z, 1e-9, "z follows z0 + vz t")
  expect.le(worst_y, 0, "y follows the parabola within g h t / 2")
  expect.near(px1, px0, 1e-9 * math.abs(px0), "horizontal momentum kept")
end

test("a thrown w:rope's centre of mass follows the parabola", function()
  local w = wobble.world{}
  local rope = w:rope{ from = { 0, 2, 0 }, to = { 1, 2, 0 }, segments = 20, mass = 1 }
  fly(w, rope, "rope")
end)

test("a thrown w:lattice's centre of mass follows the parabola", function()
  local w = wobble.world{}
  local b = w:lattice{ min = { 0, 2, 0 }, max = { 0.4, 2.4, 0.4 }, res = { 4, 4, 4 }, mass = 2 }
  fly(w, b, "lattice")
end)

test("a thrown, spinning lattice's centre of mass still follows the parabola", function()
  local w = wobble.world{}
  local b = w:lattice{ min = { 0, 2, 0 }, max = { 0.4, 2.4, 0.4 }, res = { 4, 4, 4 }, mass = 2 }
  -- give it V plus a spin of 6 rad/s about z through its centre (0.2, 2.2)
  for _, p in ipairs(b.particles) do
    local x, y = w:position(p)
    w:set_velocity(p, V[1] - 6 * (y - 2.2), V[2] + 6 * (x - 0.2), V[3])
  end
  local x0, y0, z0 = com(w, b)
  local h = w:dt() / w:substeps()
  local worst = -math.huge
  w:run{ seconds = 1, on_frame = function(w, f, t)
    local x, y, z = com(w, b)
    local e = math.sqrt((x - x0 - V[1] * t) ^ 2 + (y - (y0 + V[2] * t - g * t * t / 2)) ^ 2 + (z - z0 - V[3] * t) ^ 2)
    worst = math.max(worst, e - (g * h * t / 2 + 1e-9))
  end }
  print(string.format("spinning lattice: COM error beyond the O(h) offset %.2e m", worst))
  expect.le(worst, 0, "COM on the parabola")
end)
