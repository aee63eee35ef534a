-- self_collide.lua: what self-collision costs, each scene against itself without it in the
-- same process (the goals of self-collision at scale: at most 1.3x for a hanging cloth, a
-- flat one and a hand-built one lying flat, at most 3x for a heap). 10 substeps x 1 iteration, one thread.
--  self128   a w:cloth of 128 x 128 (2 m, radius half its spacing), pinned at two
--            corners, swinging down for 60 frames: self_collide = true against false
--  self32, self64, self128_30, self256: the same spacing (2 m / 127) for 30 frames at
--            each size (0.5 m to 4 m), with the cost per particle of the contacts and of
--            their broad phase (the aim: flat)
--  loose128  the same sheet built by hand (w:particle + w:distance: loose particles,
--            default radius 0.02 > half the 1.57 cm spacing): contacts on against off
--  looseflat128  that sheet dropped 5 cm onto the floor, lying flat there for 60 frames
--            (the hand-built aim as the issue measured it: loose particles touching
--            nothing but their neighbours): contacts on against off
--  drape128  a w:cloth of 128 x 128 (1.5 m) draped over a sphere on the floor (60 frames
--            after it fell 3 cm onto it): self_collide = true against false
--  flat128   a w:cloth of 128 x 128 (2 m) dropped 5 cm onto the floor, lying flat there
--            for 60 frames (the issue's flat cloth): self_collide = true against false
--  heap128   a w:cloth of 128 x 128 (1.5 m) hung straight down over the floor, rippled,
--            let fall into a heap on itself for 120 frames: self_collide = true against
--            false (without, the folds pass through each other)
-- Columns as the other scenes'; the note gives both frames and their ratio.
-- Run: make bench   (or build/wobble bench [--json]; --set frames=N for a quick look)
local bench = require("wobble.bench")
local args = wobble.args

-- an n x n cloth at self128's spacing (2 m at 128: the same radius and the same motion in
-- radii at every size, so that the rows compare the cost of more particles, not of a
-- finer cloth)
local function hanging_n(n)
  local L = 2 * (n - 1) / 127
  return function(self)
    local w = wobble.world{ threads = args.threads or 1 }
    local c = w:cloth{ origin = {-L / 2, 2, -L / 2}, size = {L, L}, res = {n, n}, mass = 1, self_collide = self }
    w:pin(c.particles[1])
    w:pin(c.particles[n])
    return w
  end
end
local hanging = hanging_n(128)

-- the 128 x 128 sheet built by hand at height y (loose particles, default radius): pinned
-- at two corners, or over the floor
local function hand_sheet(contacts, y, floor)
  local w = wobble.world{ threads = args.threads or 1, contacts = contacts }
  if floor then w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 } end
  local n, s, id = 128, 2 / 127, {}
  for j = 0, n - 1 do
    for i = 0, n - 1 do id[j * n + i] = w:particle{ pos = {i * s - 1, y, j * s - 1}, mass = 1 / (n * n) } end
  end
  for j = 0, n - 1 do
    for i = 0, n - 1 do
      if i < n - 1 then w:distance(id[j * n + i], id[j * n + i + 1]) end
      if j < n - 1 then w:distance(id[j * n + i], id[(j + 1) * n + i]) end
    end
  end
  if not floor then
    w:pin(id[0])
    w:pin(id[n - 1])
  end
  return w
end
local function hand_built(contacts) return hand_sheet(contacts, 2, false) end
-- dropped 5 cm onto the floor, lying flat there (the issue's hand-built aim: loose
-- particles that touch nothing but their neighbours)
local function hand_flat(contacts) return hand_sheet(contacts, 0.05, true) end

-- a flat cloth: dropped 5 cm onto the floor, where it lies
local function lying(self)
  local w = wobble.world{ threads = args.threads or 1 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
  w:cloth{ origin = {-1, 0.05, -1}, size = {2, 2}, res = {128, 128}, mass = 1, self_collide = self }
  return w
end

local function heap(self)
  local w = wobble.world{ threads = args.threads or 1, damping = 0.5 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8 }
  local c = w:cloth{ origin = {-0.75, 0, 0}, size = {1.5, 1.5}, res = {128, 128}, mass = 1, self_collide = self,
                     friction = 0.8, compliance = 1e-6 }
  -- the sheet as built lies in x-z; stand it up in x-y, its lower edge 2 radii above the floor
  local r = w:radius(c.particles[1])
  for _, p in ipairs(c.particles) do
    local x, _, z = w:position(p)
    w:set_position(p, x, z + 2 * r, 0.02 * math.sin(20 * z + 2 * x))
    w:set_velocity(p, -0.3 * x * z, 0, 0.2 * math.sin(9 * z + 1.5 * x))
  end
  return w
end

-- a w:cloth of 128 x 128 (1.5 m) let fall from 3 cm onto a sphere (radius 0.5 m) on the
-- floor, measured once it has draped over it (after 60 frames): the issue's "gently
-- draped" cloth
local function draped(self)
  local w = wobble.world{ threads = args.threads or 1, damping = 0.5 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
  w:collider{ shape = "sphere", center = {0, 0.5, 0}, radius = 0.5, friction = 0.5 }
  w:cloth{ origin = {-0.75, 1.03, -0.75}, size = {1.5, 1.5}, res = {128, 128}, mass = 1, self_collide = self,
           friction = 0.5 }
  for _ = 1, 60 do w:step() end
  return w
end

-- ms per frame of frames steps; the stats of the last
local function run(w, frames)
  local step_ms, solve_ms, projections, broad_ms = 0, 0, 0, 0
  for _ = 1, frames do
    w:step()
    local s = w:stats()
    step_ms, solve_ms, projections = step_ms + s.step_ms, solve_ms + s.solve_ms, projections + s.projections
    broad_ms = broad_ms + s.broad_ms
  end
  return step_ms / frames, solve_ms, projections, w:stats(), broad_ms / frames
end

local function scene(name, make, frames, what)
  if not bench.want(name) then return end
  frames = bench.frames(frames)
  collectgarbage()
  local rss0 = bench.rss()
  local w = make(true)
  local ms, solve_ms, projections, s, broad_ms = run(w, frames)
  local bytes = bench.bytes_per(rss0, s.particles)
  local contacts = s.particle_contacts
  w = nil
  collectgarbage()
  local ms_off = run(make(false), frames)
  local r = {
    scene = name, particles = s.particles, constraints = s.distances, substeps = s.substeps,
    iterations = s.iterations, threads = s.threads, frames = frames, ms_per_frame = ms,
    ms_per_frame_off = ms_off, ratio_off = ms / ms_off,
    ns_per_projection = ms * frames * 1e6 / projections, ns_per_projection_solve = solve_ms * 1e6 / projections,
    bytes_per_particle = bytes,
  }
  -- per particle: what the contacts add to the frame, and the broad phase's part of it
  r.ns_per_particle_contacts = (ms - ms_off) * 1e6 / s.particles
  r.ns_per_particle_broad = broad_ms * 1e6 / s.particles
  bench.report(r, string.format("%s: %.3f ms/frame, %.2fx; %d contacts at the end; per particle %.0f ns "
                                .. "(broad phase %.0f)", what, ms_off, r.ratio_off, contacts,
                                r.ns_per_particle_contacts, r.ns_per_particle_broad))
end

scene("self128", hanging, 60, "without self-collision")
-- the same hanging cloth at other sizes, at the same spacing: the aim is a flat cost per
-- particle from 32^2 to 256^2 (within 30%)
scene("self32", hanging_n(32), 30, "without self-collision")
scene("self64", hanging_n(64), 30, "without self-collision")
scene("self128_30", hanging, 30, "without self-collision")
scene("self256", hanging_n(256), 30, "without self-collision")
scene("flat128", lying, 60, "without self-collision")
scene("loose128", hand_built, 60, "contacts = false")
scene("looseflat128", hand_flat, 60, "contacts = false")
scene("heap128", heap, 120, "without self-collision")
scene("drape128", draped, 60, "without self-collision")
