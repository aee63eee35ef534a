-- rigid_stack.lua: boxes resting on boxes with friction (XPBD rigid bodies, Müller et al.
-- 2020 §3.5): stacks, overhangs, boxes on box and mesh colliders, a sphere on a capsule,
-- a box sliding to a stop on another box. dt = 1/60 s, 10 substeps: h = 1/600 s.
--
-- Tolerances. Gravity sinks a body g h^2 = 2.7e-5 m per substep and the contacts lift it
-- back; one Gauss-Seidel pass per substep leaves the boxes of a stack of 5 sunk into each
-- other by a fixed 1.9e-4 m at the top (it does not grow): heights within 1 mm of
-- (2 i - 1) half-heights. Creep is tested by the motion between t = 5 s and 10 s: under
-- 1e-6 m, and speeds under 1e-6 m/s and rad/s, 1e-4 of g h (1.6e-2 m/s, the speed one
-- substep of gravity gives). Before the fix the stack of 5 moved at 8 cm/s and spun at
-- 0.05 rad/s; without friction the nudged top box slides off. Between two bodies static
-- friction is positional too (§3.5), applied after the substep's normal sweeps (see
-- rigid.c): with friction only in the velocity pass the nudged stack crept at 2e-6 m/s
-- per box (7e-5 m in all over 10 s); now it is held to 1.4e-7 m in all over 10 s, tested
-- at 1e-6 m (7 x the measured value, 1/70 of the old creep).

local g = 9.81

local function speeds(b)
  local vx, vy, vz = b:velocity()
  local ox, oy, oz = b:angular_velocity()
  return math.sqrt(vx * vx + vy * vy + vz * vz), math.sqrt(ox * ox + oy * oy + oz * oz)
end

local function run_to(w, t) while w:time() < t - 1e-9 do w:step() end end

-- boxes of half {0.3, 0.2, 0.3} on a plane: box i at x = off[i], resting on box i - 1
local function stack(n, mu, off, vtop)
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = mu }
  local bs = {}
  for i = 1, n do
    bs[i] = w:rigid{ shape = "box", half = {0.3, 0.2, 0.3}, mass = 1, friction = mu,
                     pos = {off and off[i] or 0, 0.2 + 0.4 * (i - 1), 0},
                     vel = i == n and vtop or nil }
  end
  return w, bs
end

test("a stack of 5 boxes with friction stands still: no creep, no spin, the nudged top box sticks", function()
  -- the top box is launched at 5 cm/s: friction stops it within v^2 / (2 mu g) = 0.25 mm
  -- (the box below is dragged a little too); without friction it slides off in 6 s
  local w, bs = stack(5, 0.5, nil, {0.05, 0, 0})
  run_to(w, 5)
  local p5 = {}
  for i = 1, 5 do p5[i] = { bs[i]:position() } end
  run_to(w, 10)
  for i = 1, 5 do
    local x, y, z = bs[i]:position()
    expect.near(y, 0.2 + 0.4 * (i - 1), 1e-3, "height of box " .. i)
    expect.lt(math.abs(x), 3e-3, "x of box " .. i) -- the nudge spreads down: 1.8 mm at the top
    expect.lt(math.abs(z), 1e-6, "z of box " .. i)
    local d = math.abs(x - p5[i][1]) + math.abs(y - p5[i][2]) + math.abs(z - p5[i][3])
    expect.lt(d, 1e-6, "box " .. i .. " crept between 5 s and 10 s")
    local v, om = speeds(bs[i])
    expect.lt(v, 1e-6, "speed of box " .. i)
    expect.lt(om, 1e-6, "spin of box " .. i)
    local qw = bs[i]:rotation()
    expect.near(math.abs(qw), 1, 1e-9, "box " .. i .. " turned")
  end
end)

test("a nudged stack of 5 boxes does not creep: total drift over 10 s under 1e-6 m", function()
  -- the top box launched at 5 cm/s stops in 2 s; then 10 s watched. Position-level static
  -- friction between the boxes holds them: 1.4e-7 m in all (measured); friction in the
  -- velocity pass only let each box creep at 2e-6 m/s, 7e-5 m in all
  local w, bs = stack(5, 0.5, nil, {0.05, 0, 0})
  run_to(w, 2)
  local p0 = {}
  for i = 1, 5 do p0[i] = { bs[i]:position() } end
  run_to(w, 12)
  local drift = 0
  for i = 1, 5 do
    local x, y, z = bs[i]:position()
    drift = drift + math.sqrt((x - p0[i][1]) ^ 2 + (y - p0[i][2]) ^ 2 + (z - p0[i][3]) ^ 2)
  end
  expect.lt(drift, 1e-6, "total drift of the 5 boxes over 10 s")
  -- the top box stopped on the one below about v^2 / (2 mu g) = 0.25 mm from where it
  -- started (measured 0.29 mm: the static correction holds it from the substep it meets
  -- the cone, not at the end of the slide); 0.2 mm .. 0.4 mm
  local rel = bs[5]:position() - bs[4]:position()
  expect.gt(rel, 2e-4, "the nudged box slid")
  expect.lt(rel, 4e-4, "the nudged box stopped by friction")
end)

test("a stack of 10 boxes with friction stands for 10 s", function()
  local w, bs = stack(10, 0.5)
  run_to(w, 10)
  for i = 1, 10 do
    local x, y, z = bs[i]:position()
    expect.near(y, 0.2 + 0.4 * (i - 1), 2e-3, "height of box " .. i)
    expect.lt(math.abs(x) + math.abs(z), 1e-6, "drift of box " .. i)
    local v, om = speeds(bs[i])
    expect.lt(v + om, 1e-6, "motion of box " .. i)
  end
end)

test("an offset box stands while its centre of mass is over the box below, topples past the edge", function()
  -- box 2 set 0.2 m off box 1's centre: its centre of mass over box 1's face (|x| <= 0.3),
  -- no friction needed; before the fix it crept with box 1, 15 cm in 10 s
  local w, bs = stack(2, 0.5, {0, 0.2})
  run_to(w, 5)
  for i = 1, 2 do
    local x, y = bs[i]:position()
    expect.near(x, 0.2 * (i - 1), 1e-4, "x of box " .. i)
    expect.near(y, 0.2 + 0.4 * (i - 1), 1e-3, "height of box " .. i)
    local v, om = speeds(bs[i])
    expect.lt(v + om, 1e-6, "motion of box " .. i)
  end
  -- a staircase of three, 0.15 m apart: the top two's centre of mass (0.225) over the
  -- bottom face, the top one's (0.3) over the middle face (-0.15..0.45): it stands (the
  -- off-centre loads settle within a mm)
  local w3, b3 = stack(3, 0.5, {0, 0.15, 0.3})
  run_to(w3, 5)
  for i = 1, 3 do
    local x, y = b3[i]:position()
    expect.near(x, 0.15 * (i - 1), 2e-3, "staircase: x of box " .. i)
    expect.near(y, 0.2 + 0.4 * (i - 1), 1e-3, "staircase: height of box " .. i)
  end
  -- box 2 at 0.45: its centre 0.15 m past box 1's edge at 0.3; it tips over the edge and
  -- falls to the ground, box 1 stays
  local w2, bt = stack(2, 0.5, {0, 0.45})
  run_to(w2, 3)
  local _, y = bt[2]:position()
  expect.lt(y, 0.35, "the overhanging box fell")
  local x1, y1 = bt[1]:position()
  expect.near(y1, 0.2, 1e-3, "the lower box stays on the ground")
  expect.lt(math.abs(x1), 0.05, "the lower box stays")
end)

test("a box rests on a box collider and on a mesh collider, nudged, and sticks", function()
  local quad = wobble.mesh{ vertices = {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}},
                            triangles = {{1, 3, 2}, {1, 4, 3}} }
  for _, kind in ipairs{"box", "mesh"} do
    local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
    if kind == "box" then
      w:collider{ shape = "box", center = {0, -0.5, 0}, half = {2, 0.5, 2}, friction = 0.5 }
    else
      w:collider{ shape = "mesh", mesh = quad, friction = 0.5 }
    end
    -- launched at 0.1 m/s: stops within v^2 / (2 mu g) = 1.0 mm
    local b = w:rigid{ shape = "box", half = {0.3, 0.2, 0.3}, mass = 1, friction = 0.5,
                       pos = {0, 0.2, 0}, vel = {0.1, 0, 0} }
    run_to(w, 5)
    local x, y, z = b:position()
    expect.near(x, 0.1 ^ 2 / (2 * 0.5 * g), 2e-4, kind .. ": stopping distance")
    expect.near(y, 0.2, 1e-6, kind .. ": height")
    expect.lt(math.abs(z), 1e-5, kind .. ": z")
    local v, om = speeds(b)
    expect.lt(v + om, 1e-6, kind .. ": motion")
  end
end)

test("a sphere rests on the top of a capsule collider", function()
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  w:collider{ shape = "capsule", a = {-1, 0, 0}, b = {1, 0, 0}, radius = 0.2, friction = 0.5 }
  local s = w:rigid{ shape = "sphere", radius = 0.3, mass = 1, friction = 0.5, pos = {0.4, 0.5, 0} }
  run_to(w, 2)
  local x, y, z = s:position()
  expect.near(y, 0.5, 1e-6, "height: the radii's sum")
  expect.near(x, 0.4, 1e-9, "along the axis")
  expect.lt(math.abs(z), 1e-9, "across")
  local v, om = speeds(s)
  expect.lt(v + om, 1e-6, "motion")
end)

test("a box sliding onto another box stops after v0^2 / (2 mu g) on it", function()
  -- the lower box (10 kg) is held by the ground's friction, mu (M + m) g > mu m g, so the
  -- upper box decelerates at mu g relative to it; 2% as rigid_contact.lua's slide
  local v0, mu = 2, 0.3
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = mu }
  local low = w:rigid{ shape = "box", half = {3, 0.2, 1}, mass = 10, friction = mu, pos = {0, 0.2, 0} }
  local top = w:rigid{ shape = "box", half = {0.2, 0.1, 0.2}, mass = 1, friction = mu,
                       pos = {-2, 0.5, 0}, vel = {v0, 0, 0} }
  run_to(w, 3)
  local x = top:position()
  local lx = low:position()
  expect.near(x - lx - (-2), v0 * v0 / (2 * mu * g), 0.02 * v0 * v0 / (2 * mu * g), "relative stopping distance")
  local v, om = speeds(top)
  expect.lt(v + om, 1e-6, "stopped")
  expect.lt(math.abs(lx), 1e-6, "the lower box held by the ground")
end)
