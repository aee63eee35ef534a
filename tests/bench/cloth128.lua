-- cloth128.lua: the cloth benchmark scenes (named after the main one).
-- An n x n cloth (structural + shear links: one diagonal per cell, alternating; 48,641
-- links at n = 128), 16 mm between neighbours (2 m across at n = 128), total mass 1,
-- pinned at two corners of one edge, falls from 1 m onto a ground plane and swings on it:
-- 10 substeps x 1 iteration, no damping, no friction.
--   cloth128, cloth128_t2   the big cloth, 1 and 2 threads, 120 frames
--   cloth32, cloth32_t2     a small one over 3000 frames: the per-frame overhead
--   scale32 ... scale512    the scaling table, 20 frames (6 at 512^2; all before the cloth
--                           reaches the ground): ns per projection should stay flat
-- Figures per scene (wobble.bench): ms per frame (w:stats().step_ms, the whole step; and
-- CPU ms per frame, the process's CPU time over the loop, steadier on a busy machine), ns
-- per projection all-in (the step / its projections) and in the projection loop alone,
-- bytes per particle (the process's resident memory growth; --unsafe), and with
-- --set bullet=PATH the same scene in Bullet's btSoftBody (tests/bench/bullet_cloth.cpp,
-- a process of its own: substeps -> internal steps, iterations -> piterations) and the
-- ratio Bullet time / wobble time (> 1: wobble is faster), of wall and (1 thread) CPU time.
-- One untimed frame first in both engines (colouring, first-step set-up).
-- Run: make bench   (or build/wobble bench [--json] [--set scenes=cloth32 --frames 5])
local bench = require("wobble.bench")

local SPACING = 2 / 127
local scenes = {
  { name = "cloth128", n = 128, frames = 120, threads = 1 },
  { name = "cloth128_t2", n = 128, frames = 120, threads = 2 },
  { name = "cloth32", n = 32, frames = 3000, threads = 1 },
  { name = "cloth32_t2", n = 32, frames = 3000, threads = 2 },
  { name = "scale32", n = 32, frames = 20, threads = 1 },
  { name = "scale64", n = 64, frames = 20, threads = 1 },
  { name = "scale128", n = 128, frames = 20, threads = 1 },
  { name = "scale256", n = 256, frames = 20, threads = 1 },
  { name = "scale512", n = 512, frames = 6, threads = 1 },
}

local function run(sc)
  local n, frames = sc.n, bench.frames(sc.frames)
  local size, height, mass, substeps, iterations = SPACING * (n - 1), 1, 1, 10, 1
  collectgarbage()
  local rss0 = bench.rss()
  local w = wobble.world{ substeps = substeps, iterations = iterations, threads = sc.threads }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  local cloth = w:cloth{ origin = {-size / 2, height, -size / 2}, size = {size, size}, res = {n, n}, mass = mass,
                         shear = true }
  w:pin(cloth.particles[1])
  w:pin(cloth.particles[n])
  w:step()   -- untimed: the first step colours the constraints

  local step_ms, solve_ms, projections = 0, 0, 0
  local cpu0 = os.clock()
  for _ = 1, frames do
    w:step()
    local s = w:stats()
    step_ms, solve_ms, projections = step_ms + s.step_ms, solve_ms + s.solve_ms, projections + s.projections
  end
  local cpu = os.clock() - cpu0   -- the process's CPU time: all threads, the loop included
  local s = w:stats()
  local r = {
    scene = sc.name, particles = s.particles, constraints = s.distances, colours = s.colours,
    substeps = s.substeps, iterations = s.iterations, threads = s.threads, frames = frames,
    ms_per_frame = step_ms / frames,
    cpu_ms_per_frame = cpu * 1e3 / frames,
    ns_per_projection = step_ms * 1e6 / projections,          -- whole step / projections
    ns_per_projection_solve = solve_ms * 1e6 / projections,   -- the projection loop alone
    bytes_per_particle = bench.bytes_per(rss0, s.particles),
    precision = bench.precision(),
    bullet_ms_per_frame = bench.null, bullet_ratio = bench.null, bullet_ratio_cpu = bench.null,
  }
  w = nil
  collectgarbage()
  local b = bench.bullet{ n = n, frames = frames, substeps = substeps, iterations = iterations, size = size,
                          height = height, mass = mass, radius = 0.02 }
  local note
  if b then
    r.bullet_ms_per_frame = b.ms_per_frame
    r.bullet_ratio = b.ms_per_frame / r.ms_per_frame
    -- CPU time: steadier than the wall clock on a shared machine, but with threads it
    -- adds up every thread's time (spinning included), so it is compared at 1 thread only
    r.bullet_cpu_ms_per_frame = b.cpu_ms_per_frame or bench.null
    r.bullet_ratio_cpu = (sc.threads == 1 and b.cpu_ms_per_frame) and b.cpu_ms_per_frame / r.cpu_ms_per_frame
                         or bench.null
    r.bullet_ns_per_projection = b.ns_per_projection
    r.bullet_bytes_per_particle = b.bytes_per_particle > 0 and b.bytes_per_particle or bench.null
    r.bullet_links = b.links
    note = string.format("bullet: %d links, %.2f ns/proj, %.0f B/part", b.links, b.ns_per_projection,
                         b.bytes_per_particle)
  end
  bench.report(r, note)
end

for _, sc in ipairs(scenes) do
  if bench.want(sc.name) then run(sc) end
end
