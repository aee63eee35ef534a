-- render_fxaa.lua: one sample with FXAA (what `wobble run --record` draws with) against
-- one sample without and 4x multisampling: FXAA changes only pixels at the edges of what
-- is drawn, brings them nearer the multisampled picture, and leaves the ground and the
-- sky (filled on the CPU with one sample) as they are.
local W, H = 320, 180
local plain = wobble.renderer{ width = W, height = H, samples = 1 }
local fx = wobble.renderer{ width = W, height = H, samples = 1, fxaa = true }
local ms = wobble.renderer{ width = W, height = H, samples = 4 }

local w = wobble.world{}
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
w:collider{ shape = "sphere", center = {0, 0.5, 0}, radius = 0.5 }
w:collider{ shape = "box", center = {1.1, 0.3, -0.3}, half = {0.3, 0.3, 0.3}, rotation = {0.92, 0, 0.38, 0} }
w:particle{ pos = {-1, 1.2, 0}, mass = 0 }
local cam = { eye = {0.3, 1.4, 4}, target = {0.2, 0.5, 0}, fov = 40 }
local frames = {}
for name, r in pairs{ plain = plain, fx = fx, ms = ms } do
  r:camera(cam)
  r:draw(w)
  frames[name] = r:image()
end

-- summed |difference| of two frames (RGB bytes) and how many pixels differ
local function diff(a, b)
  local sum, n = 0, 0
  for i = 1, #a, 3 do
    local d = math.abs(a:byte(i) - b:byte(i)) + math.abs(a:byte(i + 1) - b:byte(i + 1)) + math.abs(a:byte(i + 2) - b:byte(i + 2))
    sum = sum + d
    if d > 0 then n = n + 1 end
  end
  return sum, n
end

test("r:info() says whether FXAA is on", function()
  expect.eq(select(3, fx:info()), true)
  expect.eq(select(3, plain:info()), false)
  expect.eq(select(2, fx:info()), 1)
end)

test("FXAA changes the edges only, towards the 4-sample picture", function()
  local _, changed = diff(frames.plain, frames.fx)
  -- the sphere's, the box's and the particle's outlines: a few hundred pixels here
  expect.gt(changed, 100, "FXAA blended the edges")
  expect.lt(changed, W * H / 20, "... and left the rest alone")
  -- where one sample is far from four (more than 30 levels summed over R, G, B: the
  -- outlines' steps), FXAA's pixel is nearer four's; measured: 202 of 213 pixels
  -- nearer, the summed difference 16065 -> 8335
  local a, b, c = frames.plain, frames.fx, frames.ms
  local edge, nearer, err_plain, err_fx = 0, 0, 0, 0
  for i = 1, #a, 3 do
    local dp, df = 0, 0
    for k = 0, 2 do
      dp = dp + math.abs(a:byte(i + k) - c:byte(i + k))
      df = df + math.abs(b:byte(i + k) - c:byte(i + k))
    end
    if dp > 30 then
      edge = edge + 1
      if df < dp then nearer = nearer + 1 end
      err_plain, err_fx = err_plain + dp, err_fx + df
    end
  end
  expect.gt(edge, 100, "one sample has steps where four have ramps")
  expect.gt(nearer, 0.8 * edge, "FXAA's edge pixels are nearer the 4-sample ones")
  expect.lt(err_fx, 0.7 * err_plain, "... by much")
end)

test("the ground and the sky are the same with one sample (sky on the CPU) and four", function()
  for _, p in ipairs{ { 2, 2 }, { W - 3, 2 }, { 2, H - 3 }, { W - 3, H - 3 }, { W // 2, 1 } } do
    local a = { fx:pixel(p[1], p[2]) }
    local b = { ms:pixel(p[1], p[2]) }
    local c = { plain:pixel(p[1], p[2]) }
    for k = 1, 3 do
      expect.near(a[k], b[k], 1, "pixel " .. p[1] .. "," .. p[2])
      expect.eq(a[k], c[k], "FXAA leaves pixel " .. p[1] .. "," .. p[2] .. " alone")
    end
  end
end)
