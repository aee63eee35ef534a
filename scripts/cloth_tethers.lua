-- cloth_tethers.lua: two 1 m cloths (48 x 48, hard links) hang from two corners side by
-- side at the default 10 substeps x 1 iteration. The left one has only its links, which
-- one pass a substep cannot make hold: it hangs about 8% longer than it is. The right one
-- has body:tether_to_pins() (long-range attachments, Kim et al. 2012: each particle held
-- within its rest distance of its nearest pin): it hangs its own length.
-- Run: build/wobble run scripts/cloth_tethers.lua
--      build/wobble test scripts/cloth_tethers.lua   (runs it and checks both)
local args = wobble.args
local n = args.res or 48
local w = wobble.world{ damping = 1 } -- (a light drag: they come to rest in a few seconds)
wobble.camera{ eye = { 0, 1.4, 3.6 }, target = { 0, 1.4, 0 }, fov = 45 }
-- the ground, 0.9 m under the hanging cloths: in the picture they hang, they do not stand
w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0 }

local function hang(x0, tethers)
  local c = w:cloth{ origin = { x0, 2, 0 }, size = { 1, 1 }, res = { n, n }, mass = 0.1 }
  w:pin(c.particles[1])
  w:pin(c.particles[n])
  if tethers then c:tether_to_pins() end
  return c
end
local plain, tethered = hang(-1.25, false), hang(0.25, true)

-- how much longer than 1 m a cloth hangs: its free edge's mean depth below the pins
local function longer(c)
  local drop = 0
  for i = 1, n do drop = drop + (2 - select(2, w:position(c.particles[(n - 1) * n + i]))) / n end
  return drop - 1
end

w:run{ seconds = args.seconds or 5 }
local a, b = longer(plain), longer(tethered)
print(string.format("links only: hangs %.1f%% longer than it is; with %d tethers: %.1f%%", 100 * a, w:tether_count(), 100 * b))

if test then -- under `wobble test`: the header's claim
  test("the tethered cloth hangs its own length, the other one stretched", function()
    expect.gt(a, 0.05, "links only: more than 5% longer")
    expect.lt(math.abs(b), 0.03, "tethered: within 3% of its length")
  end)
end
