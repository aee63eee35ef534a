-- render_demo.lua: the rendering benchmark. The demo scene (scripts/cloth_clothesline.lua's
-- set-up: a 30x30 cloth pegged to a line over the ground) drawn at 1280x720 with 4x
-- multisampling, every layer on, through OSMesa (llvmpipe on the CPU).
-- Figures: ms per rendered frame (r:draw alone: shadow map, scene, resolve, read back),
-- ms per simulated frame, and ms per frame recorded to MP4 (draw + encode queue).
-- wobble.clock() is wall time: os.clock() would add up llvmpipe's threads.
-- Run: make bench   (or build/wobble bench; --set frames=N for a quick look)
local args = wobble.args
if not require("wobble.bench").want("render_demo") then return end
local frames = args.frames or 120
local width, height = args.width or 1280, args.height or 720

local w = wobble.world{ substeps = 20, iterations = 1 }
w:collider{ shape = "capsule", a = {-1.5, 2.02, 0}, b = {1.5, 2.02, 0}, radius = 0.01 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.6 }
local res = 30
local cloth = w:cloth{ origin = {-0.75, 2, 0}, size = {1.5, 1.5}, res = {res, res},
                       mass = 0.3, compliance = 2e-6, bend_links = 1e-3 }
cloth:pin_where(function(x, y, z)
  return z < 1e-6 and (math.abs(x + 0.75) < 1e-6 or math.abs(x - 0.75) < 1e-6 or math.abs(x) < 0.76 / (res - 1))
end)

local r = wobble.renderer{ width = width, height = height, samples = 4 }
r:draw(w)   -- the first frame compiles the shaders: not counted

local step_ms, draw_ms = 0, 0
for _ = 1, frames do
  w:step()
  step_ms = step_ms + w:stats().step_ms
  local t0 = wobble.clock()
  r:draw(w)
  draw_ms = draw_ms + (wobble.clock() - t0) * 1000
end

-- recording: draw + hand the frame to the encoder thread (ffmpeg runs meanwhile)
r:record("bench_render_demo.mp4")
local t0 = wobble.clock()
for _ = 1, frames do
  w:step()
  r:draw(w)
end
local _, recorded = r:stop()
local rec_ms = (wobble.clock() - t0) * 1000 / frames

local out = {
  scene = "render_demo", width = width, height = height, frames = frames, samples = select(2, r:info()),
  ms_per_draw = draw_ms / frames, ms_per_step = step_ms / frames, ms_per_recorded_frame = rec_ms,
  recorded = recorded,
}
if args.json then
  print(string.format('{"scene": "render_demo", "width": %d, "height": %d, "frames": %d, "samples": %d, '
    .. '"ms_per_draw": %.3f, "ms_per_step": %.3f, "ms_per_recorded_frame": %.3f}', out.width, out.height,
    out.frames, out.samples, out.ms_per_draw, out.ms_per_step, out.ms_per_recorded_frame))
else
  print(string.format("%-12s %9s %7s %7s %12s %12s %16s", "scene", "size", "samples", "frames", "ms/draw",
    "ms/step", "ms/recorded"))
  print(string.format("%-12s %9s %7d %7d %12.2f %12.2f %16.2f", out.scene, width .. "x" .. height, out.samples,
    frames, out.ms_per_draw, out.ms_per_step, out.ms_per_recorded_frame))
end
