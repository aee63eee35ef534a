-- box_on_jelly.lua: a rigid box dropped on a block of jelly (two-way particle-rigid
-- contacts): the box sinks into the jelly, which bulges (its tetrahedra keep
-- their volume) and pushes back until it holds the box, wobbling, above the ground. The
-- box's weight goes into the jelly through the contacts, and the jelly's push into the
-- box: a heavier box (--set mass=20) sinks deeper.
-- Run: build/wobble run scripts/box_on_jelly.lua --record /tmp/boj/
local args = wobble.args
local M = args.mass or 6
local w = wobble.world{ substeps = 10 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8 }
local r = 0.0625
local jelly = w:lattice{ min = {-0.5, r, -0.5}, max = {0.5, 0.5 + r, 0.5}, res = {9, 5, 9}, mass = 3, radius = r,
                         compliance = 5e-3, damping = 5, tets = true, volume_compliance = 1e-4, friction = 0.5 }
local box = w:rigid{ shape = "box", half = {0.3, 0.12, 0.25}, mass = M, pos = {0.05, 1.0, 0},
                     rotation = {0.99, 0.06, 0, 0.08}, friction = 0.6 }

-- the jelly's top under the box's centre
local function top_under(x0, z0)
  local top = -math.huge
  for i = jelly.first, jelly.first + jelly.count - 1 do
    local x, y, z = w:position(i)
    if math.abs(x - x0) < 0.1 and math.abs(z - z0) < 0.1 then top = math.max(top, y) end
  end
  return top
end
local top0 = top_under(0, 0)
local lowest, most = math.huge, 0
w:run{ seconds = args.seconds or 5, on_frame = function(w)
  local _, y = box:position()
  lowest = math.min(lowest, y)
  most = math.max(most, w:stats().rigid_contacts)
end }
local bx, by, bz = box:position()
local sunk = top0 - top_under(bx, bz)
local inside = 0
for i = jelly.first, jelly.first + jelly.count - 1 do
  if box:distance(w:position(i)) < w:radius(i) - 1e-3 then inside = inside + 1 end
end
local vx, vy, vz = box:velocity()
local speed = math.sqrt(vx * vx + vy * vy + vz * vz)
print(string.format("box_on_jelly: a %.0f kg box came down to %.2f m (lowest %.2f m), the jelly %.1f cm lower under it, "
  .. "%d particles inside it, %d contacts at most, speed %.3f m/s", M, by, lowest, 100 * sunk, inside, most, speed))

if test then  -- under `wobble test`: the header's claims
  test("the jelly catches the box and holds it above the ground", function()
    -- held: its lowest face (up to the half-diagonal of a tilted box) clear of the ground
    expect.gt(lowest, 0.4, "never reached the ground")
    expect.gt(sunk, 5e-3, "the jelly gives under it")
    expect.eq(inside, 0, "no particle inside the box")
    expect.gt(most, 10, "resting on many particles")
    expect.lt(speed, 0.05, "at rest")
  end)
end
