-- shape_match.lua: meshless shape matching (w:shape_match, src/core/shape_match.c).
--
-- A cluster pulls each particle towards its goal c + R r (c the mass centre, R the
-- rotation that best fits the rest shape r onto the particles) with an XPBD zero-length
-- spring of stiffness m kappa, kappa = s / ((1 - s) (1/60 s)^2): `stiffness` s is the
-- fraction of the distance to the goal one projection of a 1/60 s step removes, and the
-- same spring at any substep. The cubes below are lattices whose own links are so soft
-- (compliance 10 m/N, a 1/600 s substep moves a link by 1e-6 of its error) that the
-- cluster alone holds their shape.

local eps = 2.0 ^ -52
local G = 9.81
local function kappa(s) return s / ((1 - s) * (1 / 60) ^ 2) end

-- a cube of res^3 particles, side 0.5 m, its bottom at height y0, shape-matched
local function cube(w, y0, opts, res)
  local b = w:lattice{ min = {-0.25, y0, -0.25}, max = {0.25, y0 + 0.5, 0.25}, res = {res or 4, res or 4, res or 4},
                       mass = 1, compliance = 10 }
  return b, opts and w:shape_match(b, opts)
end

-- every pairwise distance of the body's particles
local function distances(w, b)
  local d, P = {}, b.particles
  for i = 1, #P do
    local x1, y1, z1 = w:position(P[i])
    for j = i + 1, #P do
      local x2, y2, z2 = w:position(P[j])
      d[#d + 1] = math.sqrt((x1 - x2) ^ 2 + (y1 - y2) ^ 2 + (z1 - z2) ^ 2)
    end
  end
  return d
end

local function worst_change(a, b)
  local m = 0
  for i = 1, #a do m = math.max(m, math.abs(b[i] - a[i]) / a[i]) end
  return m
end

-- a cube dropped from 0.5 m onto the floor, 2 s (landed and settled); the largest
-- relative change of a pairwise distance at the end
local function drop(stiffness, substeps)
  local w = wobble.world{ substeps = substeps or 10 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  local b = cube(w, 0.5, stiffness and { stiffness = stiffness })
  local d0 = distances(w, b)
  w:run{ seconds = 2 }
  local lo = { w:bounds() }
  return worst_change(d0, distances(w, b)), lo[2]
end

test("stiffness 1: a dropped cluster lands rigid; at 0.1 it is far less rigid", function()
  local rigid, bottom = drop(1)
  -- it fell and lies on the floor (particle radius: half the 1/6 m spacing)
  expect.lt(bottom, 0.1)
  -- A rigid cluster is exactly its rest shape after each projection; only the floor,
  -- projected after it in the same substep, bends it: its bottom layer falls a few g h^2
  -- in a substep (2.7e-5 m at h = 1/600 s, 1.6e-4 of the 1/6 m spacing) and is pushed
  -- back. Each substep starts from the cluster refitted to that (shape_match.c), which
  -- lifts it by the bottom layer's share of the mass, f = 1/4, of that offset: at rest the
  -- offset settles at 1/f times a substep's fall (measured 2.6e-3, 6.5e-4 when the push
  -- was refitted as speed). 4e-3 is 24 g h^2: tight.
  expect.lt(rigid, 4e-3, "stiffness 1: pairwise distances after landing")
  -- the error is the floor's, O(h^2): four times the substeps, about 1/16 of it
  local rigid40 = drop(1, 40)
  expect.lt(rigid40, rigid / 8, "stiffness 1, 40 substeps")
  local soft = drop(0.1)
  -- sagging under its own weight by g / kappa = 2.5 cm at 0.1 (and jiggling), where
  -- the rigid one moved by 0.1 mm
  expect.gt(soft, 0.05, "stiffness 0.1: pairwise distances after landing")
  expect.gt(soft, 25 * rigid)
  -- without the cluster the links alone do not hold the cube at all
  expect.gt(drop(nil), 0.3, "no shape matching: the cube collapses")
end)

-- Eight particles at the corners of a cube, the top four pinned, hanging under gravity
-- (world damping settles the oscillation; it does not change the equilibrium). By
-- symmetry R = I and the mass centre (pinned particles keep their mass in the fit) sits
-- delta/2 below its rest place when the bottom four have sagged by delta, so every
-- particle is delta/2 from its goal; the spring m kappa (delta/2) holds a bottom
-- particle's weight m g: delta = 2 g / kappa. XPBD with one projection per substep
-- reaches the steady state C = g (1 + kappa h^2) / kappa (the substep's fall g h^2 on
-- top). One projection per substep: the particles fall g h^2 in the prediction, the fit's
-- centre follows half of it, and the projection takes back kappa h^2 / (1 + kappa h^2)
-- of the distance to the goal; the steady state is delta = 2 g / kappa + g h^2. More
-- iterations converge towards the implicit step's equilibrium, delta = 2 g / kappa
-- exactly, so they end between the two.
local function sag(stiffness, substeps, iterations)
  local w = wobble.world{ substeps = substeps, iterations = iterations, damping = 4 }
  local ids = {}
  for i = 0, 7 do
    local x, y, z = i % 2, (i // 2) % 2, i // 4
    ids[#ids + 1] = w:particle{ pos = {x * 0.4, 1 + y * 0.4, z * 0.4}, mass = 0.5 }
    if y == 1 then w:pin(ids[#ids]) end
  end
  local s = w:shape_match(ids, { stiffness = stiffness })
  w:run{ seconds = 5 }
  local total = 0
  for _, id in ipairs(ids) do
    local _, y = w:position(id)
    if y < 1.2 then total = total + (1 - y) end
  end
  return total / 4, w, s, ids
end

test("stiffness is a spring: the sag is 2 g / kappa at any substeps and iterations", function()
  for _, s in ipairs{ 0.1, 0.5 } do
    local k = kappa(s)
    for _, run in ipairs{ { 5, 1 }, { 10, 1 }, { 40, 1 }, { 10, 4 }, { 5, 8 } } do
      local h = 1 / 60 / run[1]
      local got = sag(s, run[1], run[2])
      local what = string.format("stiffness %g, %d substeps, %d iterations", s, run[1], run[2])
      -- the equilibrium is exact up to the damped residual motion (e^-10 after 5 s)
      -- and the rotation fit's convergence (1e-12): 1e-3 is generous
      if run[2] == 1 then
        expect.rel(got, 2 * G / k + G * h * h, 1e-3, what)
      else
        expect.ge(got, 2 * G / k * (1 - 1e-3), what)
        expect.le(got, (2 * G / k + G * h * h) * (1 + 1e-3), what)
      end
      -- the material itself does not change with the substeps: within g h^2 (2% at
      -- stiffness 0.5 and 5 substeps, 1e-4 at 0.1) of 2 g / kappa
      expect.rel(got, 2 * G / k, 0.025, what)
    end
  end
end)

test("the cluster's elastic energy is in w:energy(): 1/2 m kappa |x - goal|^2", function()
  local delta, w, s = sag(0.1, 10, 1)
  local _, pe = w:energy()
  -- gravity's part: the free particles only (pinned ones carry no energy that changes)
  local grav = 0
  for id = 1, w:particle_count() do
    if not w:pinned(id) then
      local _, y = w:position(id)
      grav = grav + w:mass(id) * G * y
    end
  end
  -- all eight particles are delta/2 from their goals
  local elastic = 8 * 0.5 * 0.5 * kappa(0.1) * (delta / 2) ^ 2
  expect.rel(pe - grav, elastic, 1e-3)
  -- the strain: RMS distance to the goals over the RMS rest radius sqrt(3) 0.2
  expect.rel(s:strain(), (delta / 2) / (math.sqrt(3) * 0.2), 1e-3)
end)

-- a cube dropped from 3 m (7.5 m/s at impact) at stiffness 0.5; its height after 5 s,
-- the first particle's rest position before and after (world damping 1/s lets the
-- undamped goal springs' jiggle die down)
local function hard_drop(opts)
  local w = wobble.world{ damping = 1 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  local b, s = cube(w, 3, opts)
  local r0 = { s:rest(1) }
  w:run{ seconds = 5 }
  local lo = { w:bounds() }
  return lo[5] - lo[2], r0, { s:rest(1) }
end

test("plastic: a cube dropped hard keeps a dent; without yield it springs back", function()
  local h, r0, r1 = hard_drop{ stiffness = 0.5, yield = 0.05, creep = 20 }
  -- the impact squashes it far past a strain of 0.05: the rest shape flowed and the cube
  -- stays flattened (measured 0.35 m of 0.5)
  expect.lt(h, 0.4, "plastic: height after landing")
  expect.gt(h, 0.1, "plastic: dented, not flattened")
  expect.gt(math.abs(r1[2] - r0[2]), 0.05, "plastic: the rest shape changed")
  local he, e0, e1 = hard_drop{ stiffness = 0.5 }
  -- elastic: back to 0.5 m, less the sag under its own weight (the floor holds the bottom
  -- layer about 3 g / kappa above its goals and the rest hang g / kappa = 2.7 mm below
  -- theirs: about 1 cm; measured 1.2 cm)
  expect.near(he, 0.5, 0.02, "elastic: height after landing")
  expect.eq(e1[2], e0[2], "elastic: the rest shape is untouched")
  -- below yield nothing flows: yield 10 is never reached
  local hy, y0, y1 = hard_drop{ stiffness = 0.5, yield = 10, creep = 20 }
  expect.eq(y1[2], y0[2], "yield never reached: the rest shape is untouched")
  expect.near(hy, 0.5, 0.02)
end)

-- a pseudo-random generator of our own (the same numbers on every platform)
local function lcg(seed)
  local s = seed
  return function()
    s = (s * 1103515245 + 12345) % 2147483648
    return s / 2147483648 - 0.5
  end
end

test("momentum is conserved to round-off in free flight", function()
  for _, stiffness in ipairs{ 1, 0.3 } do
    local w = wobble.world{ gravity = {0, 0, 0}, substeps = 10, iterations = 2 }
    local rnd = lcg(11)
    local b = w:lattice{ min = {0, 0, 0}, max = {0.4, 0.3, 0.5}, res = {3, 3, 4}, mass = 2, compliance = 10 }
    -- unequal masses: the cluster weighs by mass
    local extra = w:particle{ pos = {0.6, 0.1, 0.2}, mass = 3 }
    local ids = { extra }
    for _, p in ipairs(b.particles) do ids[#ids + 1] = p end
    w:shape_match(ids, { stiffness = stiffness })
    for id = 1, w:particle_count() do w:set_velocity(id, 2 * rnd(), 2 * rnd(), 2 * rnd()) end
    local p0 = { w:momentum() }
    local frames, sum_mx = 60, 0
    w:run{ frames = frames, on_frame = function(w)
      local s = 0
      for id = 1, w:particle_count() do
        local x, y, z = w:position(id)
        s = s + w:mass(id) * (math.abs(x) + math.abs(y) + math.abs(z))
      end
      sum_mx = math.max(sum_mx, s)
    end }
    -- Each projection moves particle i by a fraction of goal - x, with sum m (goal - x) = 0
    -- exactly; the goal c + R r and the move take about 20 roundings of relative size eps
    -- per coordinate, and a position error dx turns into a velocity error dx/h (only the
    -- fresh errors of a substep reach the momentum, as in momentum.lua)
    local n = frames * 10 * 2
    local tol = n * 20 * eps * sum_mx / (w:dt() / 10)
    local p1 = { w:momentum() }
    for i = 1, 3 do expect.near(p1[i], p0[i], tol, string.format("stiffness %g: momentum[%d]", stiffness, i)) end
    expect.lt(tol, 1e-6 * math.sqrt(p0[1] ^ 2 + p0[2] ^ 2 + p0[3] ^ 2), "the bound is round-off")
  end
end)

-- A rigid cluster meets the floor only through the particles the floor pushes. Refitted
-- from there as it was, each push was spread over the cluster as speed while the refit
-- moved those particles back into the floor by the rest, which the floor then pushed out
-- again: every push counted twice. A cube dropped flat on a floor of restitution 0
-- rebounded at 1.7 of 4.3 m/s, and one landing on an edge (tilted 0.3 rad, friction 0.6:
-- scripts/jelly_shape.lua's rigid cube) sprang off it spinning and was thrown 0.57 m,
-- where a rigid body of its shape (w:rigid, the particles' spheres included) moves 0.07 m.
local function landing(tilt)
  local H, y0, res, mu = 0.5, 1.2, 5, 0.6
  local w = wobble.world{ substeps = 10, damping = 0.5 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = mu }
  local b = w:lattice{ min = {-H / 2, y0, -H / 2}, max = {H / 2, y0 + H, H / 2}, res = {res, res, res}, mass = 2,
                       compliance = 1, friction = mu }
  local c, s = math.cos(tilt), math.sin(tilt)
  for _, p in ipairs(b.particles) do
    local px, py, pz = w:position(p)
    local dy = py - (y0 + H / 2)
    w:set_position(p, c * px - s * dy, y0 + H / 2 + s * px + c * dy, pz)
  end
  w:shape_match(b, { stiffness = 1 })
  local v = wobble.world{ substeps = 10, damping = 0.5 }
  v:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = mu }
  local r = H / (2 * (res - 1))
  local rb = v:rigid{ shape = "box", half = {H / 2 + r, H / 2 + r, H / 2 + r}, mass = 2, pos = {0, y0 + H / 2, 0},
                      rotation = {math.cos(tilt / 2), 0, 0, math.sin(tilt / 2)}, friction = mu }
  local function centre()
    local sx, sy = 0, 0
    for _, p in ipairs(b.particles) do local x, y = w:position(p); sx, sy = sx + x, sy + y end
    return sx / #b.particles, sy / #b.particles
  end
  local _, y = centre()
  local down, up = 0, 0
  for _ = 1, 240 do
    w:step(); v:step()
    local _, y1 = centre()
    local vy = (y1 - y) * 60
    down = math.min(down, vy)
    if down < -1 then up = math.max(up, vy) end
    y = y1
  end
  return { x = centre(), rx = rb:position(), down = -down, up = up }
end

test("a rigid cluster lands as a rigid body: no rebound on a floor of restitution 0, not thrown off an edge", function()
  local flat = landing(0)
  -- (centre speeds over a frame: a lift of the refit without speed shows as up to
  -- 0.13 m/s)
  expect.gt(flat.down, 4, "it fell")
  expect.lt(flat.up, 0.2, "flat: the centre's rebound (m/s)")
  local edge = landing(-0.3)
  expect.lt(math.abs(edge.rx), 0.1, "(the rigid body moves 0.07 m)")
  expect.near(edge.x, edge.rx, 0.05, "on an edge: where it comes to rest, against the rigid body's (m)")
end)

test("deterministic: the same hash for any thread count", function()
  local function run(threads)
    local w = wobble.world{ threads = threads }
    w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
    cube(w, 1, { stiffness = 0.4, yield = 0.02, creep = 5 }, 5)
    w:run{ frames = 60 }
    return w:hash()
  end
  expect.eq(run(2), run(1))
  expect.eq(run(4), run(1))
end)
