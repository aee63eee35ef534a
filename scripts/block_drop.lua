-- block_drop.lua: a soft block (a lattice of springs) dropped on the ground wobbles and
-- settles. Compliance sets how soft it is: try --set compliance=1e-3.
-- Run: build/wobble run scripts/block_drop.lua
local args = wobble.args
local w = wobble.world{ substeps = 20 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8, restitution = 0.2 }
local block = w:lattice{ min = {-0.3, 1.0, -0.3}, max = {0.3, 1.6, 0.3}, res = {6, 6, 6},
                         mass = 2, compliance = args.compliance or 1e-4, damping = 0.01 }
local lowest = math.huge
w:run{ seconds = args.seconds or 3, on_frame = function(w)
  local _, miny, _, _, maxy = w:bounds()
  lowest = math.min(lowest, maxy - miny)
end }
local _, miny, _, _, maxy = w:bounds()
print(string.format("block: %d particles; squashed to %.0f%% of its height on impact, rests %.3f m tall",
  #block.particles, 100 * lowest / 0.6, maxy - miny))
