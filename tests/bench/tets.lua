-- tets.lua: the Neo-Hookean benchmark. A 20x20x20-cell block (21^3 = 9261
-- particles, 48000 tets: 6 per cell, no links) of E = 1e5 Pa, nu = 0.3 dropped on the
-- ground: 10 substeps x 1 iteration, 120 frames.
--   tets      one thread (or --set threads=N)
--   tets_t2   two threads: the colour batches (about 2000 tets each) split on the pool
-- Figures: ms per frame (the whole step: prediction, contacts with the ground, the tets)
-- and ns per tet projection (the solver's time / (substeps x iterations x tets): both
-- constraints of one tet, the 2x2 solve), and in the note the process's CPU time per tet
-- projection (all threads; steadier than wall time on a busy machine).
-- Run: make bench   (or build/wobble bench [--json]; --set frames=N for a quick look)
local bench = require("wobble.bench")
local args = wobble.args

local function run(name, threads)
  local frames = bench.frames(120)
  collectgarbage()
  local rss0 = bench.rss()
  local w = wobble.world{ substeps = 10, iterations = 1, threads = threads }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
  w:lattice{ min = {-0.5, 0.3, -0.5}, max = {0.5, 1.3, 0.5}, res = {21, 21, 21}, mass = 100,
             tets = true, young = 1e5, poisson = 0.3, friction = 0.4 }

  local step_ms, solve_ms, projections = 0, 0, 0
  local cpu0 = os.clock()
  for _ = 1, frames do
    w:step()
    local s = w:stats()
    step_ms, solve_ms, projections = step_ms + s.step_ms, solve_ms + s.solve_ms, projections + s.projections
  end
  local cpu = os.clock() - cpu0 -- the process's CPU time: all threads, the whole loop
  local s = w:stats()
  local tets = w:tet_count()
  local n = frames * s.substeps * s.iterations * tets
  local r = {
    scene = name, particles = s.particles, tets = tets, constraints = tets,
    substeps = s.substeps, iterations = s.iterations, threads = s.threads, frames = frames,
    ms_per_frame = step_ms / frames,
    cpu_ms_per_frame = cpu * 1e3 / frames,
    ns_per_tet = solve_ms * 1e6 / n,
    cpu_ns_per_tet = cpu * 1e9 / n,                            -- the whole step's CPU time, all threads
    ns_per_projection = step_ms * 1e6 / projections,          -- whole step / projections (a tet counts one)
    ns_per_projection_solve = solve_ms * 1e6 / projections,
    bytes_per_particle = bench.bytes_per(rss0, s.particles),
  }
  bench.report(r, string.format("constraints = tets; %.1f ns/tet in the solver, %.1f ns CPU/tet (whole step)",
                                r.ns_per_tet, r.cpu_ns_per_tet))
end

if bench.want("tets") then run("tets", args.threads or 1) end
if bench.want("tets_t2") then run("tets_t2", 2) end
