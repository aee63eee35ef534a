-- rigid_boxes.lua: rigid boxes, spheres and a capsule (XPBD rigid bodies, Müller et al.
-- 2020) dropped onto the ground and onto each other. Left: three boxes dropped one above
-- the other land in turn and come to rest as a stack; a fourth, tilted, lands on the
-- stack's edge and tumbles off. Right: a box, a plank and a capsule thrown spinning tumble
-- across the ground; two balls drop on them. The boxes and the plank come to rest (the
-- capsule and the balls, round, may roll on: there is no rolling resistance); nothing sinks
-- into the ground or into another body. Try --set friction=0.1 or --set restitution=0.7.
-- Run: build/wobble run scripts/rigid_boxes.lua [--record out/rb/]
local args = wobble.args
local mu, e = args.friction or 0.5, args.restitution or 0.3
local w = wobble.world{ substeps = 10 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = mu }
local s = math.sqrt(0.5)
-- the stack: 0.3 m tall boxes, each dropped 0.15 m above where it will rest, turned a little
local stack = {}
for i = 1, 3 do
  local a = 0.15 * (i - 2)   -- turned about the vertical, so the stack is not a single block
  stack[i] = w:rigid{ shape = "box", half = {0.3, 0.15, 0.3}, mass = 2, pos = {-1.2 + 0.04 * i, 0.3 + 0.45 * (i - 1), 0},
                      rotation = {math.cos(a / 2), 0, math.sin(a / 2), 0}, restitution = e, friction = mu }
end
-- tilted 30 degrees and a third over the stack's edge: it lands on the edge and tips off
local tipper = w:rigid{ shape = "box", half = {0.15, 0.15, 0.15}, mass = 0.5, pos = {-0.8, 2.4, 0},
                        rotation = {math.cos(0.26), 0, 0, math.sin(0.26)}, restitution = e, friction = mu }
local thrown = {
  w:rigid{ shape = "box", half = {0.2, 0.2, 0.2}, mass = 1, pos = {0.6, 1.2, -0.6}, rotation = {s, s, 0, 0},
           vel = {1.5, 1, 0.5}, angular_velocity = {3, 1, 6}, restitution = e, friction = mu },
  w:rigid{ shape = "box", half = {0.5, 0.05, 0.25}, mass = 1, pos = {1.4, 1.0, 0.8}, vel = {0.5, 2, 0},
           angular_velocity = {0, 0, 6}, restitution = e, friction = mu },
  w:rigid{ shape = "capsule", a = {-0.35, 0, 0}, b = {0.35, 0, 0}, radius = 0.12, pos = {1.2, 1.8, -1.2},
           rotation = {0.9, 0, 0.3, 0.3}, vel = {0.5, 0, 0}, angular_velocity = {1, 2, 0}, restitution = e },
  w:rigid{ shape = "sphere", radius = 0.25, pos = {1.5, 3, 0.8}, restitution = 0.5 },
  w:rigid{ shape = "sphere", radius = 0.15, mass = 0.3, pos = {0.7, 3.2, -0.5}, restitution = e },
}
local bodies = { stack[1], stack[2], stack[3], tipper }
for _, b in ipairs(thrown) do bodies[#bodies + 1] = b end

-- how far each body turned in all (the angle between successive frames' rotations)
local function angle(q, r)
  local d = math.abs(q[1] * r[1] + q[2] * r[2] + q[3] * r[3] + q[4] * r[4])
  return 2 * math.acos(math.min(1, d))
end
local turned, last = {}, {}
for i, b in ipairs(bodies) do turned[i], last[i] = 0, { b:rotation() } end
local lowest = math.huge -- the lowest centre of the boxes and the plank
w:run{ seconds = args.seconds or 6, on_frame = function(w)
  for i, b in ipairs(bodies) do
    local q = { b:rotation() }
    turned[i], last[i] = turned[i] + angle(q, last[i]), q
  end
  for _, b in ipairs{ stack[1], stack[2], stack[3], thrown[2] } do
    local _, y = b:position()
    lowest = math.min(lowest, y)
  end
end }

local resting, e_k = 0, w:energy()
local still = {}  -- still[i]: body i at rest (the stack, the tipper, the thrown box, the plank: 1 to 6)
for i, b in ipairs(bodies) do
  local vx, vy, vz = b:velocity()
  still[i] = math.abs(vx) + math.abs(vy) + math.abs(vz) < 1e-3
  if still[i] then resting = resting + 1 end
end
local heights = {}
for i, b in ipairs(stack) do heights[i] = select(2, b:position()) end
local tx, ty = tipper:position()
print(string.format("rigid_boxes: %d bodies, %d at rest after %.0f s, kinetic energy %.2g J", #bodies, resting,
                    w:time(), e_k))
print(string.format("  stack: centres at %.3f, %.3f, %.3f m (boxes 0.3 m tall); tipped box turned %.0f deg, "
                    .. "rests at x = %.2f, y = %.3f", heights[1], heights[2], heights[3], math.deg(turned[4]), tx, ty))
local spun = {}
for i = 5, 7 do spun[#spun + 1] = string.format("%.0f", math.deg(turned[i])) end
print("  thrown box, plank, capsule turned " .. table.concat(spun, ", ") .. " deg; lowest box centre "
      .. string.format("%.3f m", lowest))

if test then  -- under `wobble test`: the header's claim
  test("three boxes dropped one above the other stack; a box tumbles off the stack; the rest tumble and settle",
    function()
      -- stacked: each box rests on the one below (0.3 m each), within a centimetre
      for i = 1, 3 do expect.near(heights[i], 0.15 + 0.3 * (i - 1), 0.01, "stack box " .. i .. " height") end
      for i = 2, 3 do
        local x1, _, z1 = stack[i - 1]:position()
        local x2, _, z2 = stack[i]:position()
        expect.lt(math.sqrt((x2 - x1) ^ 2 + (z2 - z1) ^ 2), 0.15, "box " .. i .. " over the one below")
      end
      -- the tipper ends on the ground (centre at its half size), off the stack, having turned
      expect.near(ty, 0.15, 0.01, "the tipped box rests on the ground")
      expect.gt(turned[4], math.rad(60), "the tipped box turned over")
      -- the thrown bodies tumble: each turned more than a half turn in all
      for i = 5, 7 do expect.gt(turned[i], math.pi, "thrown body " .. (i - 4) .. " tumbled") end
      -- none sank into the ground (the plank's half height is the lowest a centre may be)
      expect.gt(lowest, 0.05 - 1e-3, "no body sank into the ground")
      -- the capsule and the spheres may still roll (no rolling resistance): the boxes and the plank rest
      for i = 1, 6 do expect.truthy(still[i], "body " .. i .. " (a box or the plank) at rest") end
    end)
end
