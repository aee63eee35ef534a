-- contact_sheet.lua: the particle-triangle contact benchmark of issue 8. 400 small loose
-- particles (radius 0.02, a 20 x 20 grid in three layers: 1200) rain onto a coarse cloth
-- (17 x 17 particles 0.125 m apart, radius 0.02, pinned at its corners) that only its
-- triangles can hold them on, and pile up on it: 1489 particles, 10 substeps x 2
-- iterations, 300 frames, single thread (--set contacts=0: the same scene without contacts).
-- Figures as tests/bench/contacts.lua's: ms per frame (the whole step), particle contacts
-- (particle-particle and particle-triangle) in the last substep (mean over the frames), the
-- broad phases' ms per frame and their share of the step.
-- Run: make bench   (or build/wobble bench [--json]; --set frames=N for a quick look)
local args = wobble.args
local frames = args.frames or 300
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

local step_ms, broad_ms, contacts = 0, 0, 0
for _ = 1, frames do
  w:step()
  local s = w:stats()
  step_ms, broad_ms, contacts = step_ms + s.step_ms, broad_ms + s.broad_ms, contacts + s.particle_contacts
end
local s = w:stats()
local r = {
  scene = "sheet", particles = s.particles, constraints = s.distances,
  substeps = s.substeps, iterations = s.iterations, threads = s.threads, frames = frames,
  ms_per_frame = step_ms / frames,
  contacts_per_frame = contacts / frames,
  broad_ms_per_frame = broad_ms / frames,
  broad_share = broad_ms / step_ms,
}
if args.json then
  print(require("wobble.bench").json(r))
else
  print(string.format("%-10s %9s %11s %8s %6s %10s %10s %12s %8s", "scene", "particles", "constraints",
    "substeps", "iters", "ms/frame", "contacts", "broad ms/fr", "broad %"))
  print(string.format("%-10s %9d %11d %8d %6d %10.3f %10.1f %12.3f %8.1f", r.scene, r.particles, r.constraints,
    r.substeps, r.iterations, r.ms_per_frame, r.contacts_per_frame, r.broad_ms_per_frame, 100 * r.broad_share))
end
