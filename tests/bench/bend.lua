-- bend.lua: the bending benchmark. The 128x128 cloth of cloth128.lua (16 mm
-- apart, 2 m across, total mass 1, structural + shear links: 48,641) with a dihedral bend
-- on every interior edge (48,133 bends, compliance 100 rad/(N m) as the cloth scripts),
-- unpinned, dropped from 1.2 m onto a sphere (radius 0.5, friction 0.3) over the ground:
-- it drapes over the sphere. 10 substeps x 1 iteration, 120 frames, single thread
-- (--set threads=N: the batches above 256 bends split across threads).
-- Figures: ms per frame (the whole step), ns per projection (all-in and the solver's, a
-- bend and a link each count one) and ns per bend projection: the solver's time with the
-- bends less the solver's time of the same cloth without them (a second world, run after
-- the first, not in the table), over substeps x iterations x bends. Wall time, so noisy
-- on a busy machine; --set bends=0 runs the cloth without bends alone.
-- Run: make bench   (or build/wobble bench --set scenes=bend [--json] [--frames N])
local bench = require("wobble.bench")
local args = wobble.args
if not bench.want("bend") then return end
local frames = bench.frames(120)
local N, SIZE = 128, 2

-- one run: the world's summed figures over the frames (the first step, which colours
-- the constraints, untimed)
local function run(with_bends)
  local w = wobble.world{ substeps = 10, iterations = 1, threads = args.threads or 1 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.3 }
  w:collider{ shape = "sphere", center = {0, 0.5, 0}, radius = 0.5, friction = 0.3 }
  w:cloth{ origin = {-SIZE / 2, 1.2, -SIZE / 2}, size = {SIZE, SIZE}, res = {N, N}, mass = 1, shear = true,
           bend = with_bends and 100 or nil }
  w:step()
  local t = { step_ms = 0, solve_ms = 0, projections = 0 }
  for _ = 1, frames do
    w:step()
    local s = w:stats()
    t.step_ms, t.solve_ms, t.projections = t.step_ms + s.step_ms, t.solve_ms + s.solve_ms, t.projections + s.projections
  end
  t.stats = w:stats()
  return t
end

collectgarbage()
local rss0 = bench.rss()
local with = run(args.bends ~= 0)
local s = with.stats
local r = {
  scene = "bend", particles = s.particles, constraints = s.distances + s.bends, bends = s.bends,
  substeps = s.substeps, iterations = s.iterations, threads = s.threads, frames = frames,
  ms_per_frame = with.step_ms / frames,
  ns_per_projection = with.step_ms * 1e6 / with.projections,
  ns_per_projection_solve = with.solve_ms * 1e6 / with.projections,
  bytes_per_particle = bench.bytes_per(rss0, s.particles),
  ns_per_bend = bench.null,
}
if s.bends > 0 then
  collectgarbage()
  local without = run(false)
  r.solve_ms_per_frame_no_bends = without.solve_ms / frames
  r.ns_per_bend = (with.solve_ms - without.solve_ms) * 1e6 / (frames * s.substeps * s.iterations * s.bends)
end
bench.report(r, string.format("constraints = links + bends (%d); %s ns per bend projection", s.bends,
                              r.ns_per_bend == bench.null and "-" or string.format("%.1f", r.ns_per_bend)))
