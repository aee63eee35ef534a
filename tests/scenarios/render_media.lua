-- render_media.lua: what the renderer writes: PNG files (read back byte for byte),
-- MP4 and GIF videos through ffmpeg (frame count, size and codec through ffprobe),
-- folders of numbered PNGs, w:run's plot, and the errors for bad paths and options.

local W, H = 96, 64
local r = wobble.renderer{ width = W, height = H }

local function scene()
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  local rope = w:rope{ from = {-0.5, 1, 0}, to = {0.5, 1, 0}, segments = 6 }
  w:pin(rope.particles[1])
  return w
end

test("save_png writes the frame, right side up, byte for byte", function()
  local w = scene()
  r:draw(w)
  r:save_png("render_media/frame.png")
  local iw, ih, px = wobble.read_png("render_media/frame.png")
  expect.eq(iw, W); expect.eq(ih, H)
  expect.truthy(px == r:image(), "the PNG holds exactly the frame")
  local info = wobble.probe("render_media/frame.png")
  expect.eq(info.width, W); expect.eq(info.codec, "png"); expect.eq(info.frames, 1)
end)

test("an MP4 has one H.264 yuv420p frame per draw", function()
  local w = scene()
  r:record("render_media/clip.mp4")
  expect.eq(select(2, r:recording()), 0)
  for _ = 1, 7 do
    w:step()
    r:draw(w)
  end
  local path, n = r:stop()
  expect.eq(n, 7)
  expect.truthy(path:match("clip%.mp4$"))
  expect.falsy(r:recording())
  local info = assert(wobble.probe("render_media/clip.mp4"))
  expect.eq(info.frames, 7); expect.eq(info.codec, "h264"); expect.eq(info.pix_fmt, "yuv420p")
  expect.eq(info.width, W); expect.eq(info.height, H)
end)

test("odd sizes are padded for yuv420p", function()
  local odd = wobble.renderer{ width = 33, height = 21, backend = "null" }
  odd:record("render_media/odd.mp4", { fps = 30 })
  local w = scene()
  for _ = 1, 3 do odd:draw(w) end
  expect.eq(select(2, odd:stop()), 3)
  local info = assert(wobble.probe("render_media/odd.mp4"))
  expect.eq(info.frames, 3); expect.eq(info.width, 34); expect.eq(info.height, 22)
  odd:close()
end)

test("a GIF has one frame per draw", function()
  local w = scene()
  r:record("render_media/clip.gif", { fps = 25 })
  for _ = 1, 5 do
    w:step()
    r:draw(w)
  end
  expect.eq(select(2, r:stop()), 5)
  local info = assert(wobble.probe("render_media/clip.gif"))
  expect.eq(info.frames, 5); expect.eq(info.codec, "gif"); expect.eq(info.width, W)
end)

test("a folder gets numbered PNG frames", function()
  local w = scene()
  r:record("render_media/frames/")
  for _ = 1, 3 do
    w:step()
    r:draw(w)
  end
  expect.eq(select(2, r:stop()), 3)
  local iw, ih, px = wobble.read_png("render_media/frames/frame_000002.png")
  expect.eq(iw, W); expect.eq(ih, H)
  expect.truthy(px == r:image(), "the last frame is frame_000002")
  expect.falsy(wobble.read_png("render_media/frames/frame_000003.png"))
end)

test("bad paths, extensions and states are clear errors", function()
  local w = scene()
  expect.error(function() r:record("render_media/clip.avi") end, "unknown extension '.avi'")
  expect.error(function() r:save_png("/nonexistent-dir/x.png") end, "outside the output folder")
  expect.error(function() r:record("/tmp/x.mp4") end, "outside the output folder")
  expect.error(function() r:stop() end, "not recording")
  r:record("render_media/twice.gif")
  expect.error(function() r:record("render_media/again.gif") end, "already recording")
  r:stop()   -- no frames: nothing is left behind
  expect.falsy(wobble.probe("render_media/twice.gif"))
  local fresh = wobble.renderer{ width = 8, height = 8, backend = "null" }
  expect.error(function() fresh:save_png("render_media/none.png") end, "call r:draw")
  fresh:close()
  fresh:close()   -- twice is fine
  expect.error(function() fresh:draw(w) end, "closed renderer")
  local nothing, msg = wobble.probe("render_media/missing.mp4")
  expect.eq(nothing, nil); expect.truthy(msg:match("missing%.mp4"))
end)

test("bad options name the key", function()
  local w = scene()
  expect.error(function() wobble.renderer{ width = 0 } end, "width")
  expect.error(function() wobble.renderer{ widht = 10 } end, "widht")
  expect.error(function() wobble.renderer{ backend = "vulkan" } end, "vulkan")
  expect.error(function() r:draw(w, { partciles = false }) end, "partciles")
  expect.error(function() r:draw(w, { particles = 1 }) end, "particles")
  expect.error(function() r:draw(w, { strain_scale = 0 }) end, "strain_scale")
  expect.error(function() r:draw({}) end, "wobble.world expected")
  expect.error(function() r:camera{ eye = {0, 0, 0}, target = {0, 0, 0} } end, "must differ")
  expect.error(function() r:camera{ eye = {0, 1, 0}, target = {0, 0, 0} } end, "up")
  expect.error(function() r:camera{ eye = {0, 0, 1}, target = {0, 0, 0}, fov = 200 } end, "fov")
  expect.error(function() r:camera{ eye = {0, 0, 1}, target = {0, 0, 0}, zoom = 2 } end, "zoom")
  expect.error(function() r:record("render_media/x.mp4", { fps = -1 }) end, "fps")
  expect.error(function() r:pixel(W, 0) end, "out of range")
end)

test("w:run{plot = ...} draws energy, strain and error over time", function()
  local w = scene()
  w:run{ frames = 40, plot = "render_media/energy.png" }
  local iw, ih, px = wobble.read_png("render_media/energy.png")
  expect.eq(iw, 960); expect.eq(ih, 720)
  -- the kinetic energy's red and the potential's blue are on the chart
  local red, blue = 0, 0
  for i = 1, #px, 3 do
    local cr, cg, cb = px:byte(i, i + 2)
    if cr > 180 and cg < 90 and cb < 90 then red = red + 1 end
    if cb > 150 and cr < 80 and cg < 150 then blue = blue + 1 end
  end
  expect.gt(red, 100, "kinetic energy drawn"); expect.gt(blue, 100, "potential energy drawn")
  expect.error(function() w:run{ frames = 1, plot = 3 } end, "plot")
  expect.error(function() w:run{ frames = 1, plot = "energy.jpg" } end, "png")
  expect.error(function() w:run{ frames = 1, plot = "/tmp/energy.png" } end, "outside the output folder")
end)
