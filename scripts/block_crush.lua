-- block_crush.lua: a rigid box, moved by the script, comes down on a soft block and
-- crushes it against the ground, then lifts off (the reference thesis's crush scene).
-- Run: build/wobble run scripts/block_crush.lua
local w = wobble.world{ substeps = 20, iterations = 2 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8 }
-- the block's particles have a contact radius of half their spacing (0.0625 m); its
-- bottom layer starts just above the ground by that, so it rests where it is made (one
-- made inside the ground rises out of it gently, at max_depenetration)
local y0 = wobble.args.y0 or 0.07
local block = w:lattice{ min = {-0.4, y0, -0.4}, max = {0.4, y0 + 0.5, 0.4}, res = {7, 5, 7},
                         mass = 3, compliance = 2e-4, damping = 0.02 }
local press = w:collider{ shape = "box", center = {0, 1.2, 0}, half = {0.6, 0.1, 0.6}, friction = 0.4 }
local seconds = wobble.args.seconds or 4
local min_height, early_top = math.huge, -math.huge
w:run{ seconds = seconds, on_frame = function(w, f, t)
  -- down at 0.5 m/s for 1.4 s (to 40% of the block's height), hold, then up
  local y = t < 1.4 and 1.2 - 0.5 * t or (t < 2.2 and 0.5 or 0.5 + 0.5 * (t - 2.2))
  press:set_position(0, y, 0)
  local _, miny, _, _, maxy = w:bounds()
  min_height = math.min(min_height, maxy - miny)
  -- before the press comes near (its face still 0.9 m up at 0.4 s) the block rests where made
  if t < 0.4 then early_top = math.max(early_top, maxy) end
end }
local _, miny, _, _, maxy = w:bounds()
print(string.format("crush: block 0.50 m tall pressed to %.3f m, recovered to %.3f m", min_height, maxy - miny))

if test then  -- under `wobble test`: the header's claim
  test("the block rests on the ground, is crushed by the box and recovers", function()
    expect.lt(early_top, y0 + 0.5 + 0.01, "the block's top stays where it was made until the box comes")
    expect.lt(min_height, 0.5 * 0.7, "the box presses it to under 70% of its height")
    expect.gt(maxy - miny, 0.5 * 0.98, "it springs back to within 2% of its height")
  end)
end
