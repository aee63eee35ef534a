-- record.lua: the recording benchmark (`make bench`'s row `record`). The demo scene
-- (scripts/cloth_clothesline.lua's set-up: a 30x30 cloth pegged to a line over the
-- ground, settled for a second) drawn at 1280x720 with one sample and FXAA and every
-- layer through OSMesa (llvmpipe on the CPU), as `wobble run --record` draws it
-- (--set samples=4: with 4x multisampling instead, as `--record --samples 4`).
-- Figures, wall clock (wobble.clock; os.clock would add up llvmpipe's threads):
--   ms/draw   r:draw alone (shadow map, scene, resolve, read back)
--   ms/step   one simulated frame
--   rec fps   frames a second of a recording to MP4, drawing and encoding (ffmpeg runs
--             meanwhile on the other core; the file finished included), the simulation's
--             time taken out; `all fps` with it
-- ms_per_frame in the JSON row is ms per recorded frame (make bench keeps the lowest).
-- Run: make bench, or build/wobble bench --unsafe --set scenes=record [--frames N]
local args = wobble.args
local bench = require("wobble.bench")
if not bench.want("record") then return end
local frames = bench.frames(120)
local width, height = args.width or 1280, args.height or 720

local w = wobble.world{ substeps = 20, iterations = 1, damping = 0.5 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.6 }
local res = 30
local cloth = w:cloth{ origin = {-0.75, 2, 0}, size = {1.5, 1.5}, res = {res, res},
                       mass = 0.3, compliance = 2e-6, bend = 100 }
local r0 = w:radius(cloth.particles[1])
w:collider{ shape = "capsule", a = {-1.5, 2 + r0 + 0.011, 0}, b = {1.5, 2 + r0 + 0.011, 0}, radius = 0.01 }
cloth:pin_where(function(x, y, z)
  return z < 1e-6 and (math.abs(x + 0.75) < 1e-6 or math.abs(x - 0.75) < 1e-6 or math.abs(x) < 0.76 / (res - 1))
end)
for _ = 1, 60 do w:step() end   -- swinging, not falling: the frames the demo shows most

local samples = args.samples or 1
local r = wobble.renderer{ width = width, height = height, samples = samples, fxaa = samples == 1 }
r:draw(w)   -- the first frame compiles the shaders: not counted

local step_ms, draw_ms = 0, 0
for _ = 1, frames do
  local t0 = wobble.clock()
  w:step()
  local t1 = wobble.clock()
  r:draw(w)
  local t2 = wobble.clock()
  step_ms, draw_ms = step_ms + (t1 - t0) * 1000, draw_ms + (t2 - t1) * 1000
end

-- recording: draw and hand the frame to the encoder's writer thread; r:stop() waits
-- for ffmpeg to finish the file
local rec_step = 0
r:record("bench_record.mp4")
local t0 = wobble.clock()
for _ = 1, frames do
  local s0 = wobble.clock()
  w:step()
  rec_step = rec_step + (wobble.clock() - s0)
  r:draw(w)
end
local _, recorded = r:stop()
local total = wobble.clock() - t0
local rec_s = total - rec_step

local out = {
  scene = "record", width = width, height = height, size = width .. "x" .. height, frames = recorded,
  samples = select(2, r:info()), fxaa = select(3, r:info()),
  ms_per_draw = draw_ms / frames, ms_per_step = step_ms / frames, ms_per_frame = 1000 * rec_s / recorded,
  fps_recording = recorded / rec_s, fps_with_step = recorded / total,
}
-- its own columns, the rest of the reporting as every scene's
bench.report(out, nil, {
  { "scene", "%-12s", "%-12s" }, { "size", "%9s", "%9s" }, { "samples", "%7s", "%7d" }, { "fxaa", "%5s", "%5s" },
  { "frames", "%6s", "%6d" },
  { "ms_per_draw", "%9s", "%9.2f", "ms/draw" }, { "ms_per_step", "%9s", "%9.2f", "ms/step" },
  { "fps_recording", "%9s", "%9.1f", "rec fps" }, { "fps_with_step", "%9s", "%9.1f", "all fps" },
})
