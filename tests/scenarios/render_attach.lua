-- render_attach.lua: the renderer marks attached particles (green) and grabbed ones
-- (magenta) as it marks pins, and draws a grab's line to its target, pixel by pixel.

local W, H = 160, 120
local r = wobble.renderer{ width = W, height = H, samples = 4 }

local function at(x, y, z)
  local px, py = r:project(x, y, z)
  expect.truthy(px and px >= 0 and px < W and py >= 0 and py < H, "point inside the frame")
  return r:pixel(px, py)
end
local function is_green(cr, cg, cb) return cg > cr + 40 and cg > cb + 40 end
local function is_magenta(cr, cg, cb) return cr > cg + 60 and cb > cg + 60 end

test("attached and grabbed particles are marked, a grab's line reaches its target", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local c = w:collider{ shape = "sphere", center = {-1.5, 0, 0}, radius = 0.1 }
  local a = w:particle{ pos = {-0.8, 1, 0}, radius = 0.08 }
  local g = w:particle{ pos = {0.5, 1, 0}, radius = 0.08 }
  r:camera{ eye = {0, 1, 4}, target = {0, 1, 0} }
  r:draw(w, { grid = false })
  local cr, cg, cb = at(-0.8, 1, 0)
  expect.falsy(is_green(cr, cg, cb), "a plain particle is not green")
  expect.falsy(is_magenta(at(0.5, 1, 0)), "nor magenta")
  w:attach(a, c)
  w:grab(g, {1.5, 1, 0})
  r:draw(w, { grid = false })
  cr, cg, cb = at(-0.8, 1, 0)
  expect.truthy(is_green(cr, cg, cb), "attached: green (" .. cr .. "," .. cg .. "," .. cb .. ")")
  cr, cg, cb = at(0.5, 1, 0)
  expect.truthy(is_magenta(cr, cg, cb), "grabbed: magenta (" .. cr .. "," .. cg .. "," .. cb .. ")")
  cr, cg, cb = at(1.5, 1, 0)
  expect.truthy(is_magenta(cr, cg, cb), "its target: magenta (" .. cr .. "," .. cg .. "," .. cb .. ")")
  -- the line: magenta somewhere on the column halfway between particle and target
  local px, py = r:project(1.0, 1, 0)
  local found = false
  for dy = -2, 2 do
    local qr, qg, qb = r:pixel(px, py + dy)
    if is_magenta(qr, qg, qb) then found = true end
  end
  expect.truthy(found, "the grab's line between them")
  -- no marks when pins are off
  r:draw(w, { grid = false, pins = false })
  expect.falsy(is_magenta(at(1.5, 1, 0)), "no target mark without pins")
end)
