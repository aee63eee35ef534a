-- made_overlapping.lua: a body made overlapping a collider or a rigid body is not a
-- collision (docs/physics.md, "Made overlapping").
--
-- The builders give a particle half its body's spacing as contact radius, so a lattice
-- made from y = 0 on the ground has its bottom layer half inside it. An overlap a
-- particle (or a rigid body) already had when the substep began goes out at no more than
-- max_depenetration (world option, 0.25 m/s by default) and adds no speed; what the
-- substep drove in is pushed out in full (src/core/collide.c made_contact, rigid.c
-- made_left, rigid_particle.c). Before, the ground pushed the whole overlap out within one
-- substep and the links carried it to the rest of the body: the 0.6 m block below left the
-- ground at 14 m/s (measured: mean 14.4 m/s after one frame, up to 15.7 m/s).
--
-- Bounds. The bottom layer rises at exactly max_depenetration (vmax), a position change
-- (x_prev moves with x): after one frame it is vmax dt higher (1e-9 m). The rest of the
-- block is pulled up by its links: for it the rise starts as a step of the base's speed
-- from 0 to vmax, which an elastic body follows with an overshoot of at most that step
-- (a mass on a spring whose end starts moving at v from rest swings between 0 and 2 v),
-- so no particle is faster than 2 vmax (measured 1.47 vmax in the first frame, vmax after
-- the third). The centre of mass of a block made 1 cm in rises at no more than vmax
-- (measured 0.94 vmax). When the bottom layer is out the block stops (the links' overshoot
-- lifts it 1.3 mm and it settles) with its bottom layer at y = r.
--
-- With the limit off the made cases fail:
--   build/wobble test tests/validation/made_overlapping.lua --set max_depenetration=1e9
-- (the old behaviour: the block leaves at 14 m/s, the stack is thrown 9.6 m, the rigid box
-- jumps its 1 cm in one frame, the particle leaves the box at 2.1 m/s). The dropped block
-- is the other side and passes with or without the limit: what a substep drives in is
-- pushed out in full, or the block would sink into the ground by (v - vmax) dt per frame;
-- so is the particle under four others, pushed into the ground by their repairs.

local VMAX = 0.25 -- the default max_depenetration, m/s
local dt = 1 / 60
local off = wobble.args.max_depenetration -- nil: the default

local function world(t)
  t = t or {}
  t.max_depenetration = off
  return wobble.world(t)
end

local function fastest(w)
  local m = 0
  for i = 1, w:particle_count() do
    local x, y, z = w:velocity(i)
    m = math.max(m, math.sqrt(x * x + y * y + z * z))
  end
  return m
end

local function low(w, body)
  local m = math.huge
  for _, p in ipairs(body.particles) do m = math.min(m, (select(2, w:position(p)))) end
  return m
end

local function com_y(w, body) -- height and vertical speed of the centre (equal masses)
  local y, vy = 0, 0
  for _, p in ipairs(body.particles) do
    y = y + select(2, w:position(p))
    vy = vy + select(2, w:velocity(p))
  end
  return y / #body.particles, vy / #body.particles
end

-- a closed flat slab of triangles, top face at y = 0: a mesh ground
local function slab()
  local v = { {-2, -1, -2}, {2, -1, -2}, {2, -1, 2}, {-2, -1, 2}, {-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2} }
  local t = { {1, 2, 3}, {1, 3, 4}, {5, 7, 6}, {5, 8, 7}, {1, 5, 6}, {1, 6, 2},
              {2, 6, 7}, {2, 7, 3}, {3, 7, 8}, {3, 8, 4}, {4, 8, 5}, {4, 5, 1} }
  return wobble.mesh{ vertices = v, triangles = t }
end

-- the ground in each of the collision pass's paths: one static plane (and its AVX2
-- groups), several static planes, any collider (a box, a closed mesh)
local grounds = {
  plane = function(w) w:collider{ shape = "plane" } end,
  ["two planes"] = function(w)
    w:collider{ shape = "plane" }
    w:collider{ shape = "plane", normal = {1, 0, 0}, offset = -5 } -- a wall far off
  end,
  box = function(w) w:collider{ shape = "box", center = {0, -1, 0}, half = {3, 1, 3} } end,
  mesh = function(w) w:collider{ shape = "mesh", mesh = slab() } end,
}

for _, name in ipairs{ "plane", "two planes", "box", "mesh" } do
  test("a 0.6 m lattice made from y = 0 on the ground (" .. name .. ") rises at max_depenetration to rest at y = r", function()
    local w = world()
    grounds[name](w)
    local b = w:lattice{ min = {0, 0, 0}, max = {0.6, 0.6, 0.6}, res = {4, 4, 4} }
    local r = w:radius(b.particles[1])
    expect.near(r, 0.1, 1e-12, "default radius: half the spacing")
    local vmax, lowest = 0, math.huge
    w:run{ seconds = 2, on_frame = function(w, f)
      vmax = math.max(vmax, fastest(w))
      lowest = math.min(lowest, low(w, b))
      if f == 1 then expect.near(low(w, b), VMAX * dt, 1e-9, "the bottom layer's rise in the first frame") end
    end }
    expect.lt(vmax, 2 * VMAX, "no particle faster than 2 max_depenetration")
    expect.ge(lowest, 0, "never below where it was made")
    expect.near(low(w, b), r, 1e-3, "rests with its bottom layer at y = r")
    expect.lt(fastest(w), 1e-3, "at rest after 2 s")
  end)
end

test("a 0.7 m block made 1 cm inside the ground rises at no more than max_depenetration", function()
  local w = world()
  w:collider{ shape = "plane" }
  local r = 0.7 / 3 / 2 -- res 4: spacing 0.7 / 3
  local b = w:lattice{ min = {0, r - 0.01, 0}, max = {0.7, r - 0.01 + 0.7, 0.7}, res = {4, 4, 4} }
  local y0 = com_y(w, b)
  local rise, speed, vmax = 0, -math.huge, 0
  w:run{ seconds = 1, on_frame = function(w)
    local y, vy = com_y(w, b)
    rise = math.max(rise, (y - y0) / dt)
    y0 = y
    speed = math.max(speed, vy)
    vmax = math.max(vmax, fastest(w))
  end }
  expect.le(rise, VMAX, "its centre rises at most max_depenetration x dt per frame")
  expect.le(speed, VMAX, "its centre's speed")
  expect.lt(vmax, 2 * VMAX, "no particle faster than 2 max_depenetration")
  expect.near(low(w, b), r, 1e-3, "rests with its bottom layer at y = r")
end)

test("a block dropped onto the ground is still stopped in full: it neither sinks nor gains energy", function()
  -- 4.2 m/s at the ground: 7 cm a frame, all of it pushed out in the substeps that
  -- drive it in (a push limited to max_depenetration would let it sink that far). The
  -- collider's restitution is 0; the block is soft and its links give back some of their
  -- compression, but its energy (kinetic, gravity, elastic) never exceeds the start's
  local w = world()
  w:collider{ shape = "plane" }
  local b = w:lattice{ min = {0, 1, 0}, max = {0.6, 1.6, 0.6}, res = {4, 4, 4} }
  local r = w:radius(b.particles[1])
  local k0, p0 = w:energy()
  local lowest, gain, landed = math.huge, -math.huge, false
  w:run{ seconds = 4, on_frame = function(w)
    lowest = math.min(lowest, low(w, b) - r)
    local k, p = w:energy()
    gain = math.max(gain, k + p - (k0 + p0))
    landed = landed or w:stats().contacts > 0
  end }
  expect.truthy(landed, "it reached the ground")
  expect.ge(lowest, -1e-9, "no frame ends with it inside the ground")
  expect.le(gain, 1e-9 * (k0 + p0), "no energy gained")
  expect.near(low(w, b), r, 1e-3, "rests with its bottom layer at y = r")
  expect.lt(fastest(w), 1e-2, "at rest")
end)

-- two blocks, the lower made from y = 0, the upper set on it with its bottom layer in the
-- hollows of the lower's top layer (r sqrt 2 above it when touching: balls on balls
-- without friction roll into the hollows anyway, with or without this change)
for _, deep in ipairs{ 0, 0.05 } do
  test(string.format("a stack of two blocks made at ground level (the upper %g m into the lower) stays", deep), function()
    local w = world()
    w:collider{ shape = "plane" }
    local a = w:lattice{ min = {0, 0, 0}, max = {0.6, 0.6, 0.6}, res = {4, 4, 4} }
    local r = w:radius(a.particles[1])
    local y1 = 0.6 + r * math.sqrt(2) - deep
    local b = w:lattice{ min = {0.1, y1, 0.1}, max = {0.7, y1 + 0.6, 0.7}, res = {4, 4, 4} }
    local top, speed = -math.huge, 0
    w:run{ seconds = 2, on_frame = function(w)
      top = math.max(top, low(w, b))
      speed = math.max(speed, math.abs(select(2, com_y(w, a))), math.abs(select(2, com_y(w, b))))
    end }
    -- at rest: the lower's bottom layer at r, the upper in its hollows (less the sag
    -- under its weight: 1.2 mm)
    expect.near(low(w, a), r, 1e-3, "the lower block rests at y = r")
    local rest = r + 0.6 + r * math.sqrt(2)
    expect.near(low(w, b), rest, 3e-3, "the upper block rests on it")
    expect.lt(top - low(w, b), 0.01, "the upper block never rose 1 cm above where it rests")
    expect.lt(fastest(w), 1e-2, "at rest")
    -- made touching, the blocks' centres move no faster than the bound above (measured
    -- 0.40 m/s for the upper one); made inside each other the particle contacts part
    -- them too (src/core/contact.c, which measures its own bound)
    if deep == 0 then expect.lt(speed, 2 * VMAX, "the blocks' centres") end
  end)
end

test("what other contacts' repairs push into the ground goes out in full: a particle under four made inside it", function()
  -- four heavy particles made half inside a light one resting on the ground: each pair
  -- pushes it down at max_depenetration, moving x_prev with x, four times what one
  -- substep of the limit would take; the ground counts none of it as kept (the
  -- particle had none there) and puts it back each substep. Counted as made it sank
  -- 3.7 cm into the ground (measured with an x_prev overlap taken as kept)
  local w = world()
  w:collider{ shape = "plane" }
  local r = 0.05
  local p = w:particle{ pos = {0, r, 0}, mass = 0.1, radius = r }
  for k = 0, 3 do
    local a = k * math.pi / 2
    w:particle{ pos = {0.05 * math.cos(a), r + 0.06, 0.05 * math.sin(a)}, mass = 2, radius = r }
  end
  local lowest = math.huge
  w:run{ seconds = 1, on_frame = function(w) lowest = math.min(lowest, select(2, w:position(p)) - r) end }
  expect.ge(lowest, -1e-9, "no frame ends with it inside the ground")
end)

test("a rigid box made 1 cm into the ground rises at max_depenetration with no speed", function()
  local w = world()
  w:collider{ shape = "plane" }
  local rb = w:rigid{ shape = "box", half = {0.3, 0.1, 0.2}, mass = 2, pos = {0, 0.09, 0} }
  local y0 = select(2, rb:position())
  local rise, speed = 0, 0
  w:run{ seconds = 1, on_frame = function(w, f)
    local _, y = rb:position()
    rise = math.max(rise, (y - y0) / dt)
    if f == 1 then expect.near(y - y0, VMAX * dt, 1e-9, "its rise in the first frame") end
    y0 = y
    local vx, vy, vz = rb:velocity()
    local ox, oy, oz = rb:angular_velocity()
    speed = math.max(speed, math.sqrt(vx * vx + vy * vy + vz * vz) + math.sqrt(ox * ox + oy * oy + oz * oz))
  end }
  expect.le(rise, VMAX + 1e-9, "it rises at max_depenetration")
  expect.lt(speed, 1e-9, "and has no speed doing so (m/s + rad/s)")
  expect.near(select(2, rb:position()), 0.1, 1e-9, "rests on the ground")
end)

test("a rigid box made 2 cm into another parts from it at max_depenetration", function()
  local w = world()
  w:collider{ shape = "plane" }
  local a = w:rigid{ shape = "box", half = {0.3, 0.1, 0.3}, mass = 2, pos = {0, 0.1, 0} }
  local b = w:rigid{ shape = "box", half = {0.2, 0.1, 0.2}, mass = 1, pos = {0, 0.28, 0} }
  local y0 = select(2, b:position())
  local rise, speed = 0, 0
  w:run{ seconds = 1, on_frame = function(w)
    local _, y = b:position()
    rise = math.max(rise, (y - y0) / dt)
    y0 = y
    for _, body in ipairs{ a, b } do
      local vx, vy, vz = body:velocity()
      speed = math.max(speed, math.sqrt(vx * vx + vy * vy + vz * vz))
    end
  end }
  -- the upper one takes 2/3 of the push (its mass 1 to 2), the ground gives the lower one
  -- back its 1/3 as a collision: 1/3 vmax of speed for both while they part (measured
  -- 0.083 m/s), none after
  expect.le(rise, VMAX * 1.001, "the upper box rises at max_depenetration")
  expect.lt(speed, VMAX / 2, "the boxes' speeds while they part")
  expect.near(select(2, b:position()), 0.3, 1e-4, "the upper box rests on the lower")
  local vx, vy, vz = b:velocity()
  expect.lt(math.abs(vx) + math.abs(vy) + math.abs(vz), 1e-6, "at rest")
end)

test("a particle made inside a rigid box on the ground leaves it at max_depenetration", function()
  local w = world()
  w:collider{ shape = "plane" }
  local rb = w:rigid{ shape = "box", half = {0.3, 0.1, 0.3}, mass = 2, pos = {0, 0.1, 0} }
  local p = w:particle{ pos = {0, 0.17, 0}, mass = 0.1, radius = 0.05 } -- 8 cm inside its top
  local y0 = select(2, w:position(p))
  local rise, speed, bspeed = 0, 0, 0
  w:run{ seconds = 1, on_frame = function(w)
    local _, y = w:position(p)
    rise = math.max(rise, (y - y0) / dt)
    y0 = y
    speed = math.max(speed, fastest(w))
    local vx, vy, vz = rb:velocity()
    bspeed = math.max(bspeed, math.sqrt(vx * vx + vy * vy + vz * vz))
  end }
  -- the box takes its share of each push into the ground, which pushes it back as a
  -- collision and the box passes that to the particle: 1/21 vmax of speed (measured
  -- 0.0119 m/s), the particle's rise stays at vmax
  expect.le(rise, VMAX * 1.001, "the particle rises at max_depenetration")
  expect.lt(speed, VMAX / 10, "and has next to no speed")
  expect.lt(bspeed, 1e-6, "the box is not thrown")
  expect.near(select(2, w:position(p)), 0.25, 1e-5, "the particle rests on the box")
end)

-- a scene with every kind of made overlap at once, saved part way and loaded
local function everything(threads)
  local w = world{ threads = threads }
  w:collider{ shape = "plane" }
  w:lattice{ min = {0, 0, 0}, max = {0.6, 0.6, 0.6}, res = {4, 4, 4} }
  w:rigid{ shape = "box", half = {0.3, 0.1, 0.2}, mass = 2, pos = {2, 0.09, 0} }
  w:rigid{ shape = "box", half = {0.3, 0.1, 0.3}, mass = 2, pos = {-2, 0.1, 0} }
  w:rigid{ shape = "box", half = {0.2, 0.1, 0.2}, mass = 1, pos = {-2, 0.28, 0} }
  w:particle{ pos = {-2.1, 0.36, 0}, mass = 0.1, radius = 0.05 }
  return w
end

test("a snapshot taken while made overlaps part goes on as the world it was saved from", function()
  -- what each contact kept is worked out from the state at a frame's start, so nothing
  -- the snapshot does not hold changes the future
  local w = everything(1)
  w:run{ frames = 3 }
  expect.eq(w:save("made_overlapping.json"), true)
  local v = assert(wobble.load("made_overlapping.json"))
  w:run{ frames = 20 }
  v:run{ frames = 20 }
  expect.eq(v:hash(), w:hash())
end)

test("made overlaps part the same for any thread count", function()
  local hashes = {}
  for _, threads in ipairs{ 1, 3 } do
    local w = everything(threads)
    -- 4096 more particles made half in the ground: the collision pass runs in parts
    w:lattice{ min = {4, 0, 0}, max = {5.5, 1.5, 1.5}, res = {16, 16, 16} }
    w:run{ frames = 10 }
    hashes[#hashes + 1] = w:hash()
  end
  expect.eq(hashes[2], hashes[1])
end)
