-- render_camera.lua: the default camera keeps the subject in the picture. Every
-- particle is projected with r:project after every frame; the null backend keeps the
-- camera's arithmetic without drawing pixels, so these runs are fast.

local W, H = 320, 180

-- the particles of `ids` (0 = all) that land outside the frame; and how many frames
local function run_outside(w, ids, frames)
  local r = wobble.renderer{ width = W, height = H, backend = "null" }
  local bad_frames, worst = 0, 0
  w:run{ frames = frames, on_frame = function(w)
    r:draw(w)
    local out = 0
    for _, id in ipairs(ids) do
      local x, y = r:project(w:position(id))
      if not x or x < 0 or x >= W or y < 0 or y >= H then out = out + 1 end
    end
    if out > 0 then bad_frames = bad_frames + 1 end
    worst = math.max(worst, out)
  end }
  r:close()
  return bad_frames, worst
end

test("a block dropped from 5 m stays in the frame every frame", function()
  local w = wobble.world{ substeps = 20 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  local block = w:lattice{ min = {-0.3, 5.0, -0.3}, max = {0.3, 5.6, 0.3}, res = {3, 3, 3}, mass = 2,
                           compliance = 1e-4 }
  local bad, worst = run_outside(w, block.particles, 120)
  expect.eq(bad, 0, "frames with a particle outside the picture (worst " .. worst .. ")")
  local _, y = w:position(block.particles[1])
  expect.lt(y, 1, "the block did fall to the ground")
end)

test("a block dropped from 1 m is not cut at impact", function()
  local w = wobble.world{ substeps = 20 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8, restitution = 0.2 }
  local block = w:lattice{ min = {-0.3, 1.0, -0.3}, max = {0.3, 1.6, 0.3}, res = {6, 6, 6}, mass = 2,
                           compliance = 1e-4, damping = 0.01 }
  local bad, worst = run_outside(w, block.particles, 90)
  expect.eq(bad, 0, "frames with a particle outside the picture (worst " .. worst .. ")")
end)

test("the camera moves smoothly: a static point never jumps", function()
  local w = wobble.world{ substeps = 20 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8 }
  w:lattice{ min = {-0.3, 1.0, -0.3}, max = {0.3, 1.6, 0.3}, res = {4, 4, 4}, mass = 2, compliance = 1e-4 }
  local r = wobble.renderer{ width = W, height = H, backend = "null" }
  local px, py, step = nil, nil, 0
  w:run{ frames = 90, on_frame = function(w)
    r:draw(w)
    local x, y = r:project(0, 0, 0)
    if px then step = math.max(step, math.sqrt((x - px) ^ 2 + (y - py) ^ 2)) end
    px, py = x, y
  end }
  -- the ground joins the picture as the block nears it, gradually: no cut
  expect.lt(step, 0.04 * W, "largest move of the origin between two frames, pixels")
  r:close()
end)

test("a second world is framed afresh, not eased from the first", function()
  local function world_at(x)
    local w = wobble.world{}
    w:lattice{ min = {x, 1, 0}, max = {x + 0.5, 1.5, 0.5}, res = {2, 2, 2} }
    return w
  end
  local a, b = world_at(0), world_at(40)
  local r = wobble.renderer{ width = W, height = H, backend = "null" }
  for _ = 1, 10 do r:draw(a) end
  r:draw(b)
  local fresh = wobble.renderer{ width = W, height = H, backend = "null" }
  fresh:draw(b)
  local c1, c2 = r:get_camera(), fresh:get_camera()
  for k = 1, 3 do
    expect.near(c1.eye[k], c2.eye[k], 1e-9, "eye")
    expect.near(c1.target[k], c2.target[k], 1e-9, "target")
  end
  r:close(); fresh:close()
end)

test("after the subject leaves a place the frame closes in on it, eased", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local p = w:particle{ pos = {0, 1, 0}, radius = 0.05 }
  w:particle{ pos = {0.5, 1, 0}, radius = 0.05 }
  local r = wobble.renderer{ width = W, height = H, backend = "null" }
  w:set_position(p, 8, 1, 0)
  w:step(); r:draw(w)
  local far = r:get_camera()
  w:set_position(p, 0, 1, 0)   -- back: the box is too large now
  w:step(); r:draw(w)
  local next_ = r:get_camera()
  local function dist(c) return math.sqrt((c.eye[1] - c.target[1]) ^ 2 + (c.eye[2] - c.target[2]) ^ 2
                                          + (c.eye[3] - c.target[3]) ^ 2) end
  expect.gt(dist(next_), 0.9 * dist(far), "one frame later the camera is still nearly as far")
  for _ = 1, 300 do w:step(); r:draw(w) end
  expect.lt(dist(r:get_camera()), 0.5 * dist(far), "a few seconds later it has closed in")
  r:close()
end)
