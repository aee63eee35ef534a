-- contacts.lua: the contact benchmark. 27 soft blocks (4x4x4 lattices, 64
-- particles and 279 links each) dropped in a 3x3x3 heap into a box (a floor and four
-- walls) pile up and push each other: 1728 particles, 10 substeps x 2 iterations,
-- 300 frames, single thread (--set contacts=0: the same scene without contacts, for the ratio).
-- Figures: ms per frame (the whole step), particle contacts in the last substep (mean
-- over the frames), the broad phase's ms per frame and its share of the step, and the
-- broad phase as a multiple of one distance-constraint sweep (one iteration over every
-- link, the solver's projection time / (substeps x iterations)): the aim is below 1.
-- Run: make bench   (or build/wobble bench [--json]; --set frames=N for a quick look)
local bench = require("wobble.bench")
local args = wobble.args
if not bench.want("contacts") then return end
local frames = bench.frames(300)
collectgarbage()
local rss0 = bench.rss()
local w = wobble.world{ substeps = 10, iterations = 2, threads = args.threads or 1, contacts = args.contacts ~= 0 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
for _, n in ipairs{ {1, 0, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 0, -1} } do
  w:collider{ shape = "plane", normal = n, offset = -1.1, friction = 0.2 }
end
for k = 0, 26 do
  local i, j, l = k % 3, (k // 3) % 3, k // 9
  local x, y, z = -0.95 + 0.65 * i + 0.05 * l, 0.2 + 0.7 * l, -0.95 + 0.65 * j
  w:lattice{ min = {x, y, z}, max = {x + 0.5, y + 0.5, z + 0.5}, res = {4, 4, 4}, mass = 1,
             compliance = 1e-5, damping = 0.01, friction = 0.4 }
end

local step_ms, broad_ms, solve_ms, contacts, projections = 0, 0, 0, 0, 0
for _ = 1, frames do
  w:step()
  local s = w:stats()
  step_ms, broad_ms, contacts = step_ms + s.step_ms, broad_ms + s.broad_ms, contacts + s.particle_contacts
  solve_ms, projections = solve_ms + s.solve_ms, projections + s.projections
end
local s = w:stats()
local r = {
  scene = "contacts", particles = s.particles, constraints = s.distances,
  substeps = s.substeps, iterations = s.iterations, threads = s.threads, frames = frames,
  ms_per_frame = step_ms / frames,
  contacts_per_frame = contacts / frames,
  broad_ms_per_frame = broad_ms / frames,
  broad_share = broad_ms / step_ms,
  sweep_ms = solve_ms / (frames * s.substeps * s.iterations),
  ns_per_projection = step_ms * 1e6 / projections,          -- whole step / projections (links, contacts)
  ns_per_projection_solve = solve_ms * 1e6 / projections,
  bytes_per_particle = bench.bytes_per(rss0, s.particles),
}
r.broad_sweeps = r.broad_ms_per_frame / r.sweep_ms
bench.report(r, string.format("contacts %.1f, broad %.3f ms/frame (%.1f %%, %.2f sweeps)", r.contacts_per_frame,
  r.broad_ms_per_frame, 100 * r.broad_share, r.broad_sweeps))
