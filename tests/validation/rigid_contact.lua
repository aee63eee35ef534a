-- rigid_contact.lua: XPBD rigid bodies against a ground plane (Müller et al. 2020 §3.5,
-- §3.6): positional contacts, static and dynamic friction, restitution.
--
-- Resting: a box set on the plane at its half height stays there. Gravity sinks it by
-- g h^2 (2.7e-5 m at h = 1/600 s) each substep and the contact lifts it back exactly
-- (the manifold's four corners are solved together, so the push is a pure translation):
-- over 10 s it neither sinks (1e-9 m) nor drifts nor spins (1e-9 rad, rad/s). Solved
-- corner after corner, the slightly different tilts of every substep pump a spin about
-- the vertical (3e-3 rad/s after 5 s) that nothing frictionless takes back.
--
-- Sliding: a box launched at v0 on a plane with friction mu decelerates at mu g (the
-- friction impulse per substep is mu times the normal impulse, m g h) and stops after
-- v0^2 / (2 mu g). The normal velocities of the four corners are set together (one by
-- one, the pitch friction gives the box left it rising 3% of g h each substep and
-- pressing the ground 3% too lightly); measured within 1e-5 of the formula, tested at 2%.
--
-- Restitution e: a ball dropped from h bounces to e^2 h. The impact speed is read in the
-- substep it touches, up to g h late (0.4% of sqrt(2 g h) for h = 1 m), and the apex is
-- sampled every frame (v^2/2g - (v - g dt/2)^2/2g ~ 1e-3 m): within 2%.

local g = 9.81

test("a box resting on the ground stays at its half height, without drift or spin", function()
  for _, mu in ipairs{0, 0.5} do
    local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
    w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = mu }
    local b = w:rigid{ shape = "box", half = {0.5, 0.25, 0.3}, mass = 3, pos = {0.2, 0.25, -0.1} }
    for _ = 1, 600 do w:step() end
    local x, y, z = b:position()
    expect.near(y, 0.25, 1e-9, "height, mu " .. mu)
    expect.near(x, 0.2, 1e-9, "x drift"); expect.near(z, -0.1, 1e-9, "z drift")
    local qw, qx, qy, qz = b:rotation()
    expect.near(qw, 1, 1e-12); expect.near(qx, 0, 1e-9); expect.near(qy, 0, 1e-9, "turned about y"); expect.near(qz, 0, 1e-9)
    local ox, oy, oz = b:angular_velocity()
    expect.lt(math.abs(ox) + math.abs(oy) + math.abs(oz), 1e-9, "spin, mu " .. mu)
    local vx, vy, vz = b:velocity()
    expect.lt(math.abs(vx) + math.abs(vy) + math.abs(vz), 1e-9, "velocity")
  end
end)

test("a sphere and a capsule rest on the ground at their radius", function()
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  w:collider{ shape = "plane" }
  local s = w:rigid{ shape = "sphere", radius = 0.3, pos = {0, 1, 0} }
  local c = w:rigid{ shape = "capsule", a = {-0.5, 0.8, 2}, b = {0.5, 1.2, 2}, radius = 0.2 }
  for _ = 1, 300 do w:step() end
  local _, y = s:position()
  expect.near(y, 0.3, 1e-6, "sphere")
  local _, cy = c:position()
  expect.near(cy, 0.2, 1e-6, "capsule lies down")
  local qw, qx, qy, qz = c:rotation()
  -- its axis (local (1, 0.4, 0) normalised) is horizontal now
  local ax, ay = 1 / math.sqrt(1.16), 0.4 / math.sqrt(1.16)
  local uy = 2 * (qx * qy + qw * qz) * ax + (1 - 2 * (qx * qx + qz * qz)) * ay
  expect.near(uy, 0, 1e-3, "axis horizontal")
end)

test("a sliding box stops after v0^2 / (2 mu g)", function()
  local v0, mu = 3, 0.3
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  w:collider{ shape = "plane", friction = mu }
  local b = w:rigid{ shape = "box", half = {0.3, 0.1, 0.3}, pos = {0, 0.1, 0}, vel = {v0, 0, 0} }
  for _ = 1, 120 do w:step() end
  local x, y, z = b:position()
  expect.rel(x, v0 * v0 / (2 * mu * g), 0.02, "stopping distance")
  -- straight: static friction grips corner by corner as it stops (1e-6 m sideways)
  expect.near(z, 0, 1e-5, "sideways")
  expect.near(y, 0.1, 1e-6, "on the ground")
  local vx = b:velocity()
  expect.lt(math.abs(vx), 1e-9, "stopped (static friction holds it)")
end)

test("restitution e: a ball dropped from h bounces to e^2 h", function()
  local h = 1
  for _, e in ipairs{0, 0.5, 0.8} do
    local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
    w:collider{ shape = "plane" }
    local r = 0.1
    local b = w:rigid{ shape = "sphere", radius = r, pos = {0, r + h, 0}, restitution = e }
    local bounced, top = false, 0
    for _ = 1, 150 do
      w:step()
      local _, y = b:position()
      local _, vy = b:velocity()
      if vy > 0 then bounced = true end
      if bounced then top = math.max(top, y - r) end
    end
    if e == 0 then
      expect.lt(top, 1e-6, "no bounce")
    else
      expect.rel(top, e * e * h, 0.02, "bounce height, e " .. e)
    end
  end
end)

test("a rising plane lifts a box (kinematic collider, infinite mass)", function()
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  local p = w:collider{ shape = "plane" }
  local b = w:rigid{ shape = "box", half = {0.2, 0.2, 0.2}, pos = {0, 0.2, 0} }
  p:set_velocity(0, 0.5, 0)
  for _ = 1, 60 do w:step() end
  local _, y = b:position()
  expect.near(y, 0.5 + 0.2, 1e-3, "carried up 0.5 m")
  local _, vy = b:velocity()
  expect.near(vy, 0.5, 1e-2, "at the plane's speed")
end)

-- A box on a slope of angle th: with mu > tan th static friction holds it (each substep
-- gravity slides it g sin th h^2 before the velocity pass can act: without friction at
-- position level it creeps ~1 cm/s); with mu < tan th it slides down at
-- g (sin th - mu cos th) (x = a t^2 / 2, sampled per substep: within 1%).
test("a box on a slope: held by static friction, or sliding at g (sin - mu cos)", function()
  local th = math.rad(20)
  local n = {-math.sin(th), math.cos(th), 0}
  local function run(mu)
    local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
    w:collider{ shape = "plane", normal = n, friction = mu }
    local hy = 0.1
    local b = w:rigid{ shape = "box", half = {0.3, hy, 0.3}, pos = {n[1] * hy, n[2] * hy, 0},
                       rotation = {math.cos(th / 2), 0, 0, math.sin(th / 2)} }
    for _ = 1, 120 do w:step() end
    local x, y = b:position()
    -- distance along the slope, downhill = (-cos, -sin)
    return -(x - n[1] * hy) * math.cos(th) - (y - n[2] * hy) * math.sin(th)
  end
  expect.lt(math.abs(run(1.0)), 1e-5, "held (measured 3e-6, settling in the first substeps)")
  local mu = 0.2
  expect.rel(run(mu), g * (math.sin(th) - mu * math.cos(th)) * 2 * 2 / 2, 0.01, "slides")
end)

-- A solid sphere launched sliding at v0 on a plane with friction: the friction impulse
-- slows it and spins it up until its contact point stops slipping, then it rolls with
-- v = 5/7 v0 (angular momentum about the contact point is kept: m v0 r = m v r + 2/5 m r^2
-- v / r) and om = -v / r. Kinetic friction removes at most the slip left (no overshoot),
-- static friction then holds the contact: measured within 1e-6, tested at 1e-5.
test("a sliding sphere starts to roll at 5/7 of its speed", function()
  local v0, r = 2, 0.2
  local w = wobble.world{ substeps = 10 }
  w:collider{ shape = "plane", friction = 0.3 }
  local s = w:rigid{ shape = "sphere", radius = r, pos = {0, r, 0}, vel = {v0, 0, 0} }
  for _ = 1, 120 do w:step() end
  local vx = s:velocity()
  local _, _, oz = s:angular_velocity()
  expect.rel(vx, 5 / 7 * v0, 1e-5, "rolling speed")
  expect.rel(oz, -vx / r, 1e-5, "rolling without slip")
end)
