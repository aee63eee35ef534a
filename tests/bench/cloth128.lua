-- cloth128.lua: the benchmark scene of the foundation issue. A 128x128 cloth
-- (structural + shear links, ~48k constraints) pinned at two corners falls onto a
-- ground plane: 20 substeps x 1 iteration, 600 frames, single thread.
-- Figures: ms per frame (the whole step) and ns per constraint projection, both the
-- projection loop alone and the whole step divided by the projections it made.
-- Run: make bench   (or build/wobble bench [--json]; --set frames=N for a quick look)
local args = wobble.args
local frames = args.frames or 600
local w = wobble.world{ substeps = 20, iterations = 1, threads = args.threads or 1 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
local cloth = w:cloth{ origin = {-1, 1, -1}, size = {2, 2}, res = {128, 128}, mass = 1, shear = true }
w:pin(cloth.particles[1])
w:pin(cloth.particles[128])

local step_ms, solve_ms, projections = 0, 0, 0
for _ = 1, frames do
  w:step()
  local s = w:stats()
  step_ms, solve_ms, projections = step_ms + s.step_ms, solve_ms + s.solve_ms, projections + s.projections
end
local s = w:stats()
local r = {
  scene = "cloth128", particles = s.particles, constraints = s.distances, colours = s.colours,
  substeps = s.substeps, iterations = s.iterations, threads = s.threads, frames = frames,
  ms_per_frame = step_ms / frames,
  ns_per_projection = solve_ms * 1e6 / projections,          -- the projection loop alone
  ns_per_projection_step = step_ms * 1e6 / projections,      -- whole step / projections
}
if args.json then
  print(require("wobble.bench").json(r))
else
  print(string.format("%-10s %9s %11s %8s %6s %10s %12s %14s", "scene", "particles", "constraints",
    "substeps", "iters", "ms/frame", "ns/proj", "ns/proj(step)"))
  print(string.format("%-10s %9d %11d %8d %6d %10.3f %12.2f %14.2f", r.scene, r.particles, r.constraints,
    r.substeps, r.iterations, r.ms_per_frame, r.ns_per_projection, r.ns_per_projection_step))
end
