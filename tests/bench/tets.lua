-- tets.lua: the Neo-Hookean benchmark of issue 9. A 20x20x20-cell block (21^3 = 9261
-- particles, 48000 tets: 6 per cell, no links) of E = 1e5 Pa, nu = 0.3 dropped on the
-- ground: 10 substeps x 1 iteration, 120 frames, single thread. Figures: ms per frame (the
-- whole step: prediction, contacts with the ground, the tets) and ns per tet projection
-- (the solver's time / (substeps x iterations x tets): both constraints of one tet, the
-- 2x2 solve; colour batches split across threads with --set threads=N).
-- Run: make bench   (or build/wobble bench [--json]; --set frames=N for a quick look)
local bench = require("wobble.bench")
local args = wobble.args
if not bench.want("tets") then return end
local frames = bench.frames(120)
collectgarbage()
local rss0 = bench.rss()
local w = wobble.world{ substeps = 10, iterations = 1, threads = args.threads or 1 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
w:lattice{ min = {-0.5, 0.3, -0.5}, max = {0.5, 1.3, 0.5}, res = {21, 21, 21}, mass = 100,
           tets = true, young = 1e5, poisson = 0.3, friction = 0.4 }

local step_ms, solve_ms, projections = 0, 0, 0
for _ = 1, frames do
  w:step()
  local s = w:stats()
  step_ms, solve_ms, projections = step_ms + s.step_ms, solve_ms + s.solve_ms, projections + s.projections
end
local s = w:stats()
local tets = w:tet_count()
local r = {
  scene = "tets", particles = s.particles, tets = tets, constraints = tets,
  substeps = s.substeps, iterations = s.iterations, threads = s.threads, frames = frames,
  ms_per_frame = step_ms / frames,
  ns_per_tet = solve_ms * 1e6 / (frames * s.substeps * s.iterations * tets),
  ns_per_projection = step_ms * 1e6 / projections,          -- whole step / projections (a tet counts one)
  ns_per_projection_solve = solve_ms * 1e6 / projections,
  bytes_per_particle = bench.bytes_per(rss0, s.particles),
}
bench.report(r, string.format("constraints = tets; %.1f ns/tet in the solver", r.ns_per_tet))
