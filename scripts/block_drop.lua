-- block_drop.lua: a soft block (a lattice of springs) dropped on the ground squashes on
-- impact, wobbles (stretching taller than at rest on the rebound, a few hops) and settles.
-- Compliance sets how soft it is: --set compliance=3e-3 squashes half as deep, 1e-4
-- hardly at all; damping (the links' own, Macklin et al. 2016 eq. 26) how soon it settles.
-- Run: build/wobble run scripts/block_drop.lua [--record out/drop/]
local args = wobble.args
local w = wobble.world{ substeps = 20 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8, restitution = 0.2 }
local H = 0.6 -- the block's side (m)
local block = w:lattice{ min = {-H / 2, 1.0, -H / 2}, max = {H / 2, 1.0 + H, H / 2}, res = {6, 6, 6},
                         mass = 2, compliance = args.compliance or 1e-2, damping = args.damping or 0.3 }
local seconds = args.seconds or 4
-- its height over time, as a fraction of its side: the least (the squash), the most after
-- the first impact (the wobble's overshoot), and how much it still moves in the last half second
local lowest, tallest, landed, last, still = 1, 1, false, 1, 0
w:run{ seconds = seconds, on_frame = function(w, f, t)
  local _, miny, _, _, maxy = w:bounds()
  local h = (maxy - miny) / H
  lowest = math.min(lowest, h)
  landed = landed or h < 0.99
  if landed then tallest = math.max(tallest, h) end
  if t > seconds - 0.5 then still = math.max(still, math.abs(h - last)) end
  last = h
end }
print(string.format("block: %d particles; squashed to %.0f%% of its height on impact, stretched to %.0f%% on the "
                    .. "rebound, rests %.3f m tall", #block.particles, 100 * lowest, 100 * tallest, last * H))

if test then  -- under `wobble test`: the header's claim
  test("the block squashes on impact, wobbles and settles", function()
    -- measured with the defaults: 83%, 107%, then 99.1% of its side with no motion left
    expect.lt(lowest, 0.9, "squashed by more than a tenth on impact")
    expect.gt(tallest, 1.03, "stretched taller than its side on the rebound (a wobble, not a thud)")
    expect.near(last, 1, 0.02, "back to its shape at rest (less its sag under its weight)")
    expect.lt(still, 1e-3, "settled: its height changed by under 0.1% a frame in the last half second")
  end)
end
