-- trampoline.lua: boxes and a ball dropped on a cloth trampoline (two-way particle-rigid
-- contacts). The sheet is pinned along its rim; the bodies land, stretch it,
-- are thrown back up by it and settle on it, a dip under each. The cloth's particles push
-- the bodies and the bodies push the cloth: with the sheet's collision off (--set collide=0,
-- `collide = false` on the cloth) they fall through to the floor.
-- Run: build/wobble run scripts/trampoline.lua --record /tmp/trampoline/
local args = wobble.args
local w = wobble.world{ substeps = 10, damping = 0.5 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8 }
local H, n = 0.8, 25
local cloth = w:cloth{ origin = {-1, H, -1}, size = {2, 2}, res = {n, n}, mass = 1.5, compliance = 2e-4, friction = 0.4,
                        collide = args.collide ~= 0 }
cloth:pin_where(function(x, _, z) return math.abs(x) > 0.999 or math.abs(z) > 0.999 end)
local bodies = {
  w:rigid{ shape = "box", half = {0.15, 0.1, 0.12}, mass = 1, pos = {-0.4, 1.8, -0.3},
           rotation = {0.97, 0.1, 0.2, 0.05}, friction = 0.5 },
  w:rigid{ shape = "box", half = {0.12, 0.12, 0.12}, mass = 1.5, pos = {0.35, 2.3, 0.2},
           rotation = {0.9, 0.3, 0, 0.3}, friction = 0.5 },
  w:rigid{ shape = "sphere", radius = 0.14, mass = 0.8, pos = {0.0, 2.8, 0.45}, friction = 0.5 },
  w:rigid{ shape = "capsule", a = {0.3, 3.3, -0.3}, b = {0.6, 3.4, -0.2}, radius = 0.08, mass = 0.7, friction = 0.5 },
}

-- per body: lowest centre, and whether it rose again after its first dip (thrown back)
local lowest, rebound, falling, dip = {}, {}, {}, {}
for i = 1, #bodies do lowest[i], rebound[i], falling[i], dip[i] = math.huge, 0, true, math.huge end
w:run{ seconds = args.seconds or 6, on_frame = function()
  for i, b in ipairs(bodies) do
    local _, y = b:position()
    local _, vy = b:velocity()
    lowest[i] = math.min(lowest[i], y)
    if falling[i] and vy > 0 and y < H + 0.3 then falling[i], dip[i] = false, y end
    if not falling[i] then rebound[i] = math.max(rebound[i], y - dip[i]) end
  end
end }

local inside, speed = 0, 0
for i, b in ipairs(bodies) do
  for p = cloth.first, cloth.first + cloth.count - 1 do
    if b:distance(w:position(p)) < w:radius(p) - 1e-3 then inside = inside + 1 end
  end
  local vx, vy, vz = b:velocity()
  speed = math.max(speed, math.sqrt(vx * vx + vy * vy + vz * vz))
  local _, y = b:position()
  print(string.format("trampoline: body %d lowest %.2f m, thrown back up %.2f m, ends at %.2f m", i, lowest[i], rebound[i], y))
end
print(string.format("trampoline: %d cloth particles inside a body, fastest body %.3f m/s at the end", inside, speed))

if test then  -- under `wobble test`: the header's claims
  test("the sheet catches every body, throws it back up and holds it above the floor", function()
    for i = 1, #bodies do
      expect.gt(lowest[i], 0.1, "body " .. i .. " never reaches the floor")
      expect.gt(rebound[i], 0.02, "body " .. i .. " is thrown back up by the sheet")
    end
    expect.eq(inside, 0, "no cloth particle inside a body")
    expect.lt(speed, 0.2, "settling")
  end)
end
