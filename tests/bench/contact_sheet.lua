-- contact_sheet.lua: the particle-triangle contact benchmark. 400 small loose
-- particles (radius 0.02, a 20 x 20 grid in three layers: 1200) rain onto a coarse cloth
-- (17 x 17 particles 0.125 m apart, radius 0.02, pinned at its corners) that only its
-- triangles can hold them on, and pile up on it: 1489 particles, 10 substeps x 2
-- iterations, 300 frames, single thread (--set contacts=0: the same scene without contacts).
-- Figures as tests/bench/contacts.lua's: ms per frame (the whole step), particle contacts
-- (particle-particle and particle-triangle) in the last substep (mean over the frames), the
-- broad phases' ms per frame and their share of the step.
-- Run: make bench   (or build/wobble bench [--json]; --set frames=N for a quick look)
local bench = require("wobble.bench")
local args = wobble.args
if not bench.want("sheet") then return end
local frames = bench.frames(300)
collectgarbage()
local rss0 = bench.rss()
local w = wobble.world{ substeps = 10, iterations = 2, threads = args.threads or 1, contacts = args.contacts ~= 0 }
local sheet = w:cloth{ origin = {-1, 0, -1}, size = {2, 2}, res = {17, 17}, mass = 2, radius = 0.02,
                       compliance = 1e-6, friction = 0.3 }
sheet:pin_where(function(x, _, z) return math.abs(x) > 0.99 and math.abs(z) > 0.99 end)
for l = 0, 2 do
  for i = 0, 19 do
    for k = 0, 19 do
      w:particle{ pos = {-0.76 + 0.08 * i + 0.01 * l, 0.3 + 0.1 * l, -0.76 + 0.08 * k}, radius = 0.02,
                  mass = 0.002 }
    end
  end
end

local step_ms, broad_ms, contacts, solve_ms, projections = 0, 0, 0, 0, 0
for _ = 1, frames do
  w:step()
  local s = w:stats()
  step_ms, broad_ms, contacts = step_ms + s.step_ms, broad_ms + s.broad_ms, contacts + s.particle_contacts
  solve_ms, projections = solve_ms + s.solve_ms, projections + s.projections
end
local s = w:stats()
local r = {
  scene = "sheet", particles = s.particles, constraints = s.distances,
  substeps = s.substeps, iterations = s.iterations, threads = s.threads, frames = frames,
  ms_per_frame = step_ms / frames,
  contacts_per_frame = contacts / frames,
  broad_ms_per_frame = broad_ms / frames,
  broad_share = broad_ms / step_ms,
  ns_per_projection = step_ms * 1e6 / projections,          -- whole step / projections (links, contacts)
  ns_per_projection_solve = solve_ms * 1e6 / projections,
  bytes_per_particle = bench.bytes_per(rss0, s.particles),
}
bench.report(r, string.format("contacts %.1f, broad %.3f ms/frame (%.1f %%)", r.contacts_per_frame,
  r.broad_ms_per_frame, 100 * r.broad_share))
