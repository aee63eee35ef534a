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

test("videos last as long as their frames: 1 s of 60 fps, and fps honoured", function()
  local w = scene()   -- dt 1/60: 60 fps unless r:record says otherwise
  for _, case in ipairs{ { "render_media/sec.gif", nil, 60 }, { "render_media/sec.mp4", nil, 60 },
                         { "render_media/sec30.gif", 30, 30 }, { "render_media/sec12.mp4", 12, 12 } } do
    local path, fps, n = case[1], case[2], case[3]
    r:record(path, fps and { fps = fps })
    for _ = 1, n do
      w:step()
      r:draw(w)
    end
    expect.eq(select(2, r:stop()), n)
    local info = assert(wobble.probe(path))
    -- a GIF's delays are whole centiseconds: 60 fps is shown at 50 (2 cs a frame)
    expect.near(info.duration, 1.0, 0.03, path .. " plays for 1 s")
  end
end)

-- mean absolute difference per channel of two RGB strings, and the same with red and
-- blue of `b` swapped (what a BGR mix-up would give)
local function mean_diff(a, b)
  expect.eq(#a, #b, "same size")
  local d, swapped = 0, 0
  for i = 1, #a, 3 do
    local ar, ag, ab = a:byte(i, i + 2)
    local br, bg, bb = b:byte(i, i + 2)
    d = d + math.abs(ar - br) + math.abs(ag - bg) + math.abs(ab - bb)
    swapped = swapped + math.abs(ar - bb) + math.abs(ag - bg) + math.abs(ab - br)
  end
  return d / #a, swapped / #a
end

test("the pixels of a recorded video are the frames drawn: colours, order of rows", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  -- red on the left (a stretched link), the sky above, the ground below
  local a = w:particle{ pos = {-0.9, 0.9, 0}, radius = 0.01 }
  local b = w:particle{ pos = {-0.3, 0.3, 0}, radius = 0.01 }
  w:distance(a, b, { rest = 0.4 })
  local ball = w:collider{ shape = "sphere", center = {0.5, 0.4, 0}, radius = 0.3 }
  r:camera{ eye = {0, 0.8, 3}, target = {0, 0.6, 0} }
  for _, path in ipairs{ "render_media/pixels.mp4", "render_media/pixels.gif" } do
    r:record(path, { fps = 25 })
    local drawn = {}
    for i = 1, 5 do
      ball:set_position(0.7 - 0.1 * i, 0.4, 0)   -- every frame differs
      w:step()
      r:draw(w, { line_width = 6 })
      drawn[i] = r:image()
    end
    r:stop()
    for _, k in ipairs{ 0, 4 } do
      local iw, ih, px = assert(wobble.read_frame(path, k))
      expect.eq(iw, W); expect.eq(ih, H)
      local d, swapped = mean_diff(px, drawn[k + 1])
      -- H.264's 4:2:0 chroma and the GIF's 256 colours cost a few levels, no more
      expect.lt(d, 5, path .. " frame " .. k .. ": mean difference per channel")
      expect.gt(swapped, 3 * d + 5, path .. ": red and blue are where they were drawn")
      local other = mean_diff(px, drawn[k == 0 and 5 or 1])
      expect.gt(other, 2 * d, path .. ": frame " .. k .. " is that frame, not another")
    end
    -- upside down, the file's first rows would be the ground
    local d = mean_diff(select(3, wobble.read_frame(path, 0)):sub(1, W * 3 * 8), drawn[1]:sub(1, W * 3 * 8))
    expect.lt(d, 6, path .. ": the top rows are the sky, as drawn")
  end
  expect.falsy(wobble.read_frame("render_media/pixels.mp4", 99))
  r:camera()
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
  -- a PNG is written only under a .png name: not a JPEG in disguise, not a bare name
  expect.error(function() r:save_png("render_media/x.jpg") end, "%.png file name expected, got 'render_media/x.jpg'")
  expect.error(function() r:save_png("render_media/noext") end, "%.png file name expected")
  expect.error(function() r:save_png("render_media.png/x") end, "%.png file name expected")
  expect.falsy(io.open("render_media/x.jpg", "r"))
  r:save_png("render_media/UPPER.PNG")
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

test("a recording with no frames removes only the empty file it made", function()
  local f = assert(io.open("render_media/old.mp4", "w"))
  f:write("precious")
  f:close()
  r:record("render_media/old.mp4")
  expect.eq(select(2, r:stop()), 0)
  f = assert(io.open("render_media/old.mp4", "r"))
  expect.eq(f:read("a"), "precious", "the file that was there is untouched")
  f:close()
  r:record("render_media/new.gif")
  r:stop()
  expect.falsy(io.open("render_media/new.gif", "r"), "the empty file made by r:record is gone")
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
  -- the chart's layout (render_plot.c): panels from x = 90 to 936, 167 rows high, at
  -- y = 70, 283 and 496: energy, maximum strain, constraint error
  local function count(x0, x1, y0, y1, pred)
    local k = 0
    for y = y0, y1 do
      for x = x0, x1 do
        local i = 3 * (y * iw + x) + 1
        if pred(px:byte(i, i + 2)) then k = k + 1 end
      end
    end
    return k
  end
  local function ink(cr, cg, cb) return cr < 110 and cg < 110 and cb < 110 end
  local function orange(cr, cg, cb) return cr > 180 and cg > 80 and cg < 160 and cb < 80 end
  local function green(cr, cg, cb) return cg > 110 and cr < 110 and cb < 110 end
  for k, y0 in ipairs{ 70, 283, 496 } do
    -- the y axis's numbers, left of every panel
    expect.gt(count(0, 86, y0 - 4, y0 + 171, ink), 40, "panel " .. k .. " has y labels")
  end
  -- inside the panels (not their legends): the strain's orange and the error's green
  expect.gt(count(92, 934, 285, 448, orange), 150, "maximum strain drawn")
  expect.gt(count(92, 934, 498, 661, green), 150, "constraint error drawn")
  expect.eq(count(92, 934, 285, 448, green), 0, "no error curve in the strain panel")
  expect.error(function() w:run{ frames = 1, plot = 3 } end, "plot")
  expect.error(function() w:run{ frames = 1, plot = "energy.jpg" } end, "png")
  expect.error(function() w:run{ frames = 1, plot = "/tmp/energy.png" } end, "outside the output folder")
end)
