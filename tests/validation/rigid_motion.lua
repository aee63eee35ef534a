-- rigid_motion.lua: XPBD rigid bodies (Müller et al. 2020) in free flight.
--
-- Free fall: each substep adds g h to the velocity (the pose follows it, and the velocity
-- read back from the pose is the same up to rounding), so v = g t to round-off (1e-12).
--
-- Torque-free tumbling: the angular momentum L = R I R^T om is a constant of the motion.
-- The gyroscopic term is integrated implicitly (rigid.c: L turns backwards in the body
-- frame by om h, then q turns forwards by the same om h), which keeps L exactly up to
-- the fixed point's tolerance (1e-16 relative per substep) and rounding, and with the
-- midpoint angular velocity the kinetic energy too: 6000 substeps leave both within 1e-9
-- (measured: 1e-12). The paper's explicit update om += h I^-1 (-om x I om) grows |L| by
-- h^2 |om x L|^2 / (2 |L|^2) per substep (percents over these 10 s); an implicit Euler
-- form (om at the substep's end) keeps |L| but loses 4% of the energy.
--
-- Dzhanibekov: a spin about the intermediate principal axis is unstable. A box with
-- half extents (0.05, 0.2, 0.4) has I_x > I_y > I_z; spun at 10 rad/s about y with a 1e-3
-- perturbation, the perturbation grows at om sqrt((I1 - I2)(I2 - I3) / (I1 I3)) = 7.3/s and
-- the body-frame spin about y reverses within ~1 s (and back again, periodically), while
-- the same spin about x or z (the extreme axes) stays within a few perturbations of itself.

-- v in the body frame of q = (w, x, y, z): q* v q
local function to_body(qw, qx, qy, qz, vx, vy, vz)
  -- t = 2 u x v, u = -(qx, qy, qz)
  local ux, uy, uz = -qx, -qy, -qz
  local tx, ty, tz = 2 * (uy * vz - uz * vy), 2 * (uz * vx - ux * vz), 2 * (ux * vy - uy * vx)
  return vx + qw * tx + (uy * tz - uz * ty), vy + qw * ty + (uz * tx - ux * tz), vz + qw * tz + (ux * ty - uy * tx)
end
local function to_world(qw, qx, qy, qz, vx, vy, vz) return to_body(qw, -qx, -qy, -qz, vx, vy, vz) end

-- L = R I R^T om of a box of mass m, half extents h (principal axes = body axes)
local function momentum(b, m, h)
  local qw, qx, qy, qz = b:rotation()
  local ox, oy, oz = to_body(qw, qx, qy, qz, b:angular_velocity())
  local I = { m * (h[2]^2 + h[3]^2) / 3, m * (h[1]^2 + h[3]^2) / 3, m * (h[1]^2 + h[2]^2) / 3 }
  return to_world(qw, qx, qy, qz, I[1] * ox, I[2] * oy, I[3] * oz)
end

test("free fall: v = g t to round-off, x = g t^2 / 2 to the integrator's order", function()
  local g = -9.81
  local w = wobble.world{ gravity = {0, g, 0}, substeps = 10 }
  local b = w:rigid{ shape = "box", half = {0.1, 0.2, 0.3}, pos = {0, 100, 0}, angular_velocity = {0, 0, 0} }
  local s = w:rigid{ shape = "sphere", radius = 0.2, pos = {3, 100, 0}, vel = {1, 0, 0} }
  for _ = 1, 120 do w:step() end
  local t = w:time()
  local _, vy = b:velocity()
  expect.near(vy, g * t, 1e-12 * math.abs(g * t), "box vy")
  local vx, vy2 = s:velocity()
  expect.near(vx, 1, 1e-12, "sphere vx"); expect.near(vy2, g * t, 1e-12 * math.abs(g * t), "sphere vy")
  -- symplectic Euler: x = g t^2 / 2 + g t h / 2 exactly (h = dt / substeps)
  local h = 1 / 600
  local _, y = b:position()
  expect.near(y, 100 + g * t * t / 2 + g * t * h / 2, 1e-9, "box y")
  local ox, oy, oz = b:angular_velocity()
  expect.eq(ox, 0); expect.eq(oy, 0); expect.eq(oz, 0)
end)

test("a tumbling box keeps its angular momentum (norm and direction) and its energy", function()
  local m, h = 2, {0.1, 0.25, 0.4}
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = 10 }
  local b = w:rigid{ shape = "box", half = h, mass = m, rotation = {0.9, 0.3, -0.2, 0.1},
                     angular_velocity = {2, 5, -3}, pos = {1, 2, 3}, vel = {1, 0.5, 0} }
  -- w:angular_momentum() about the origin: x x m v + R I R^T om
  local s = { momentum(b, m, h) }
  local x, y, z = b:position()
  local vx, vy, vz = b:velocity()
  local l0 = { s[1] + m * (y * vz - z * vy), s[2] + m * (z * vx - x * vz), s[3] + m * (x * vy - y * vx) }
  local a = { w:angular_momentum() }
  for c = 1, 3 do expect.near(a[c], l0[c], 1e-14, "w:angular_momentum " .. c) end
  local n0 = math.sqrt(l0[1]^2 + l0[2]^2 + l0[3]^2)
  -- kinetic: m v^2 / 2 + om . I om / 2
  local k0 = w:energy()
  local qw, qx, qy, qz = b:rotation()
  local ox, oy, oz = to_body(qw, qx, qy, qz, b:angular_velocity())
  expect.near(k0, m * (1 + 0.25) / 2 + (m * (h[2]^2 + h[3]^2) / 3 * ox^2 + m * (h[1]^2 + h[3]^2) / 3 * oy^2
                                     + m * (h[1]^2 + h[2]^2) / 3 * oz^2) / 2, 1e-13, "w:energy")
  for _ = 1, 600 do
    w:step()
    local l = { w:angular_momentum() }
    for c = 1, 3 do expect.near(l[c], l0[c], 1e-9 * n0, "L component " .. c) end
    expect.rel(w:energy(), k0, 1e-9, "kinetic energy")
  end
  -- it really tumbles: om is far from its start
  ox, oy, oz = b:angular_velocity()
  expect.gt(math.abs(ox - 2) + math.abs(oy - 5) + math.abs(oz + 3), 0.5, "om changed")
  local px, py, pz = w:momentum()
  expect.near(px, m, 1e-12); expect.near(py, m * 0.5, 1e-12); expect.near(pz, 0, 1e-12)
end)

test("Dzhanibekov: a spin about the intermediate axis flips, about the others it does not", function()
  local h = {0.05, 0.2, 0.4}
  local function run(axis)
    local w = wobble.world{ gravity = {0, 0, 0}, substeps = 10 }
    local om = {1e-2, 1e-2, 1e-2}
    om[axis] = 10
    local b = w:rigid{ shape = "box", half = h, angular_velocity = om }
    local lo, hi = 10, -10
    for _ = 1, 300 do
      w:step()
      local qw, qx, qy, qz = b:rotation()
      local o = { to_body(qw, qx, qy, qz, b:angular_velocity()) }
      lo = math.min(lo, o[axis]); hi = math.max(hi, o[axis])
    end
    return lo, hi
  end
  local lo, hi = run(2)
  expect.lt(lo, -9, "the spin about y reverses")
  expect.gt(hi, 9.9, "and it began at +10")
  for _, axis in ipairs{1, 3} do
    lo = run(axis)
    expect.gt(lo, 9.9, "axis " .. axis .. " stays")
  end
end)
