-- tets.lua: the Neo-Hookean benchmark of issue 9. A 20x20x20-cell block (21^3 = 9261
-- particles, 48000 tets: 6 per cell, no links) of E = 1e5 Pa, nu = 0.3 dropped on the
-- ground: 10 substeps x 1 iteration, 120 frames, single thread. Figures: ms per frame (the
-- whole step: prediction, contacts with the ground, the tets) and ns per tet projection
-- (the solver's time / (substeps x iterations x tets): both constraints of one tet, the
-- 2x2 solve; colour batches split across threads with --set threads=N).
-- Run: make bench   (or build/wobble bench [--json]; --set frames=N for a quick look)
local args = wobble.args
local frames = args.frames or 120
local w = wobble.world{ substeps = 10, iterations = 1, threads = args.threads or 1 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
w:lattice{ min = {-0.5, 0.3, -0.5}, max = {0.5, 1.3, 0.5}, res = {21, 21, 21}, mass = 100,
           tets = true, young = 1e5, poisson = 0.3, friction = 0.4 }

local step_ms, solve_ms = 0, 0
for _ = 1, frames do
  w:step()
  local s = w:stats()
  step_ms, solve_ms = step_ms + s.step_ms, solve_ms + s.solve_ms
end
local s = w:stats()
local tets = w:tet_count()
local r = {
  scene = "tets", particles = s.particles, tets = tets,
  substeps = s.substeps, iterations = s.iterations, threads = s.threads, frames = frames,
  ms_per_frame = step_ms / frames,
  ns_per_tet = solve_ms * 1e6 / (frames * s.substeps * s.iterations * tets),
}
if args.json then
  print(require("wobble.bench").json(r))
else
  print(string.format("%-10s %9s %9s %8s %6s %10s %10s", "scene", "particles", "tets",
    "substeps", "iters", "ms/frame", "ns/tet"))
  print(string.format("%-10s %9d %9d %8d %6d %10.3f %10.1f", r.scene, r.particles, r.tets, r.substeps,
    r.iterations, r.ms_per_frame, r.ns_per_tet))
end
