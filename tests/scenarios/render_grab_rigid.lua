-- render_grab_rigid.lua: a rigid body's grab is drawn as a particle's is: a line from the
-- grabbed point of the body (not its centre) to the target, pixel by pixel.

local W, H = 160, 120
local r = wobble.renderer{ width = W, height = H, samples = 4 }
local function is_magenta(cr, cg, cb) return cr > cg + 60 and cb > cg + 60 end

-- magenta within 2 pixels above or below the projection of (x, y, z)
local function magenta_near(x, y, z)
  local px, py = r:project(x, y, z)
  expect.truthy(px and px >= 0 and px < W and py >= 0 and py < H, "point inside the frame")
  for dy = -2, 2 do
    if is_magenta(r:pixel(px, py + dy)) then return true end
  end
  return false
end

test("a rigid body's grab: the line runs from the grabbed point to the target", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local rb = w:rigid{ shape = "box", half = {0.2, 0.2, 0.2}, pos = {-1, 0.8, 0} }
  r:camera{ eye = {0, 1, 5}, target = {0, 1, 0} }
  -- the box's top right edge at (-0.8, 1, 0), pulled towards (1, 1, 0): a level line at
  -- y = 1 (from the centre it would slope from y = 0.8)
  w:grab(rb, {1, 1, 0}, { at = {0.2, 0.2, 0}, compliance = 1 })
  r:draw(w, { grid = false })
  expect.truthy(magenta_near(0.1, 1, 0), "the line, level with the grabbed edge")
  expect.truthy(magenta_near(0.6, 1, 0), "the line, near the target")
  expect.falsy(magenta_near(0.1, 0.85, 0), "not from the centre")
end)
