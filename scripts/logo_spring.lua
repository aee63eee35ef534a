-- logo_spring.lua: the logo crush of json_logo_crush.lua pressed much deeper, with each
-- letter made elastic as a whole by shape matching (w:shape_match over the letter's
-- particles, Müller et al. 2005). A box squashes the six letters of assets/logo.json to a
-- tenth of their height, holds, and lifts: distance links alone let the voxels fold
-- inside out and the letters stay flattened (--set shape=0); the clusters remember each
-- letter's shape and the letters spring back to over 80 % of their height. With
-- --set plastic=1 the clusters yield (the rest shape flows towards the crushed one past
-- a strain of `yield`): the letters keep a dent, the reference thesis's plastic
-- deformation (§3.1) for whole bodies. Drawn, the letters turn blue while squashed (the
-- clusters' strain: r:draw's materials layer).
-- Run:     build/wobble run scripts/logo_spring.lua [--record out/logo_spring/] (seen from the front, at the
--          height of the press's lowest)
-- Options: --set shape=0 (links only), --set plastic=1 (--set yield=0.1 --set creep=1.5: they
--          end at about half their height), --set stiffness=0.95 (per 1/60 s), --set gap=0.05
--          (the press's lowest, m above the ground), --set friction=1.5 (the press's: a rough
--          press holds the letters' tops, so they squash straight down rather than shear
--          over; at 0.8 the L topples onto the E), --set seconds=5
local args = wobble.args
local shape, plastic = args.shape ~= 0, args.plastic == 1
local w = wobble.world{ substeps = 20, iterations = 2 }
local logo = assert(w:load_particles("../assets/logo.json")) -- relative to this file's folder
local press = w:collider{ shape = "box", center = {0, 1.1, 0}, half = {1.3, 0.2, 0.3}, friction = args.friction or 1.5 }

for _, part in ipairs(logo.parts) do
  if shape then
    w:shape_match(part.particles, { stiffness = args.stiffness or 0.95,
                                    yield = plastic and (args.yield or 0.1) or nil,
                                    creep = plastic and (args.creep or 1.5) or nil })
  end
end

local function height(part)
  local lo, hi = math.huge, -math.huge
  for _, p in ipairs(part.particles) do
    local _, y = w:position(p)
    lo, hi = math.min(lo, y), math.max(hi, y)
  end
  return hi - lo
end

-- the camera `--record` draws with and `wobble view` starts with: in front at 7 cm, level
-- with the gap under the press (it comes down to 5 cm), so the press hides nothing
wobble.camera{ eye = {0.3, 0.07, 2.2}, target = {0, 0.3, 0} }

local rest, squashed = {}, {}
for i, part in ipairs(logo.parts) do rest[i], squashed[i] = height(part), math.huge end
local bottom = args.gap or 0.05 -- the lowest the press's bottom face comes
local down = (0.9 - bottom) / 0.4
w:run{ seconds = args.seconds or 5, on_frame = function(w, f, t)
  -- down at 0.4 m/s, hold half a second, back up at 0.4 m/s, then out of the way
  local y = t < down and 1.1 - 0.4 * t or (t < down + 0.5 and bottom + 0.2 or bottom + 0.2 + 0.4 * (t - down - 0.5))
  press:set_position(0, math.min(y, 1.1), 0)
  for i, part in ipairs(logo.parts) do squashed[i] = math.min(squashed[i], height(part)) end
end }

print(string.format("logo: %d particles in %d letters, %s", logo.count, #logo.parts,
                    shape and ((plastic and "plastic" or "elastic") .. " shape matching per letter") or "links only"))
local lowest, highest = math.huge, 0
for i, part in ipairs(logo.parts) do
  local back = height(part) / rest[i]
  lowest, highest = math.min(lowest, back), math.max(highest, back)
  print(string.format("  %-3s %2d particles: %.3f m tall, crushed to %3.0f%%, back to %3.0f%%", part.name, part.count,
                      rest[i], 100 * squashed[i] / rest[i], 100 * back))
end
local deepest = 0
for i in ipairs(logo.parts) do deepest = math.max(deepest, squashed[i] / rest[i]) end

if test then  -- under `wobble test`: the header's claim (for the options given)
  test("the press squashes every letter to under a fifth of its height", function()
    expect.lt(deepest, 0.2, "the tallest squashed letter")
  end)
  if plastic then
    test("plastic letters keep a dent", function()
      expect.lt(highest, 0.8, "every letter stays below 80 % of its height")
      expect.gt(lowest, 0.15, "but not flattened: the links and the clusters' elastic part push back")
    end)
  else
    test("elastic letters spring back to over 80 % of their height", function()
      expect.gt(lowest, 0.8, "the flattest letter after the press has gone")
    end)
  end
end
