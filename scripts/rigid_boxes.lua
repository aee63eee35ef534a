-- rigid_boxes.lua: rigid boxes, spheres and a capsule (XPBD rigid bodies, Müller et al.
-- 2020) dropped and thrown onto the ground: they tumble, bounce, slide and come to rest.
-- Bodies do not meet each other yet (the narrow phase between bodies is wired at merge),
-- so they start apart. Try --set friction=0.1 or --set restitution=0.7.
-- Run: build/wobble run scripts/rigid_boxes.lua --record /tmp/rb/
local args = wobble.args
local mu, e = args.friction or 0.5, args.restitution or 0.3
local w = wobble.world{ substeps = 10 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = mu }
local s = math.sqrt(0.5)
local bodies = {
  w:rigid{ shape = "box", half = {0.3, 0.15, 0.2}, mass = 2, pos = {-2, 1.5, 0}, rotation = {0.9, 0.3, 0.2, 0.1},
           angular_velocity = {2, 0, 3}, restitution = e },
  w:rigid{ shape = "box", half = {0.2, 0.2, 0.2}, mass = 1, pos = {0, 2.2, -1.6}, rotation = {s, s, 0, 0},
           vel = {0, 0, 0.5}, angular_velocity = {0, 4, 0}, restitution = e },
  w:rigid{ shape = "box", half = {0.5, 0.05, 0.25}, mass = 1, pos = {2, 1.0, 0.3}, vel = {0, 2, 0},
           angular_velocity = {0, 0, 6}, restitution = e },
  w:rigid{ shape = "sphere", radius = 0.25, pos = {0.3, 2.5, 1.2}, vel = {0, 0, 0.4}, restitution = 0.8 },
  w:rigid{ shape = "sphere", radius = 0.15, mass = 0.3, pos = {-1.5, 3, 2}, restitution = e },
  w:rigid{ shape = "capsule", a = {-0.35, 0, 0}, b = {0.35, 0, 0}, radius = 0.12, pos = {2, 1.8, -2},
           rotation = {0.9, 0, 0.3, 0.3}, angular_velocity = {1, 2, 0}, restitution = e },
}
local lowest = math.huge
w:run{ seconds = args.seconds or 6, on_frame = function(w)
  for _, b in ipairs(bodies) do
    local _, y = b:position()
    lowest = math.min(lowest, y)
  end
end }
-- checks: everything came to rest on the ground, none sank into it
local resting, e_k = 0, w:energy()
for _, b in ipairs(bodies) do
  local vx, vy, vz = b:velocity()
  if math.abs(vx) + math.abs(vy) + math.abs(vz) < 1e-3 then resting = resting + 1 end
end
print(string.format("rigid_boxes: %d bodies, %d at rest after %.0f s, kinetic energy %.2g J, lowest centre %.3f m",
  #bodies, resting, w:time(), e_k, lowest))
if test then  -- under `wobble test`: the header's claim
  test("the bodies land, bounce and come to rest on the ground, none sinking into it", function()
    -- the lowest centre is the thin plank's (half height 0.05) or above
    expect.gt(lowest, 0.05 - 1e-3, "no body sank into the ground")
    -- the spheres may still roll (no rolling resistance): the boxes and the capsule rest
    expect.ge(resting, 4, "bodies at rest")
  end)
end
