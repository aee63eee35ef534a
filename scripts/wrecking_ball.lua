-- wrecking_ball.lua: a rigid ball on a rope swings down and knocks over a tower of soft
-- blocks (attachments to rigid bodies and two-way particle-rigid contacts). The
-- rope hangs from a pin; its last particle is attached to the ball (w:attach(p, ball)), so
-- the rope pulls the ball round and the ball drags the rope; the ball hits the tower at
-- the bottom of its swing and the blocks fly, each pushed by the ball and by the blocks
-- around it. With the tower's collision off (--set collide=0) the ball swings through it.
-- Run: build/wobble run scripts/wrecking_ball.lua --record /tmp/wrecking/
local args = wobble.args
local w = wobble.world{ substeps = 20, iterations = 2 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8 }
local pivot, L, R = {0, 2.6, 0}, 1.6, 0.2
local rope = w:rope{ from = pivot, to = {pivot[1] + L, pivot[2], 0}, segments = 16, mass = 0.4 }
w:pin(rope.first)
local ball = w:rigid{ shape = "sphere", radius = R, mass = 12, pos = {pivot[1] + L + R, pivot[2], 0}, friction = 0.4 }
w:attach(rope.first + rope.count - 1, ball)

-- three soft blocks stacked where the ball passes the bottom of its swing
local s, r = 0.3, 0.05
local blocks = {}
for i = 0, 2 do
  local y0 = 0.005 + i * (s + 0.01)
  blocks[#blocks + 1] = w:lattice{ min = {-0.45, y0 + r, -s / 2}, max = {-0.45 + s, y0 + s + r, s / 2}, res = {4, 4, 4},
                                   mass = 2, radius = r, compliance = 1e-4, damping = 1, friction = 0.5,
                                   collide = args.collide ~= 0 }
end
local function centre(b)
  local cx, cy = 0, 0
  for p = b.first, b.first + b.count - 1 do
    local x, y = w:position(p)
    cx, cy = cx + x, cy + y
  end
  return cx / b.count, cy / b.count
end
local start = {}
for i, b in ipairs(blocks) do start[i] = { centre(b) } end

local hit_speed, after_speed, inside = 0, math.huge, 0
w:run{ seconds = args.seconds or 3, on_frame = function(w)
  local bx = ball:position()
  local vx, vy, vz = ball:velocity()
  local v = math.sqrt(vx * vx + vy * vy + vz * vz)
  if bx > -0.2 + R and bx < 0.3 then hit_speed = math.max(hit_speed, v) end       -- just before the tower
  if bx < -0.6 and after_speed == math.huge then after_speed = v end             -- just past it
  for _, b in ipairs(blocks) do
    for p = b.first, b.first + b.count - 1 do
      if ball:distance(w:position(p)) < w:radius(p) - 2e-3 then inside = inside + 1 end
    end
  end
end }

local moved = 0 -- knocked along the ball's way (-x)
for i, b in ipairs(blocks) do moved = math.max(moved, start[i][1] - centre(b)) end
print(string.format("wrecking ball: %.2f m/s before the tower, %s after it; blocks moved up to %.2f m; %d particle-frames inside the ball",
  hit_speed, after_speed < math.huge and string.format("%.2f m/s", after_speed) or "never through", moved, inside))

if test then  -- under `wobble test`: the header's claims
  test("the ball knocks the tower over and is slowed by it", function()
    expect.gt(hit_speed, 3, "the rope swings the ball down fast (sqrt(2 g L) = 5.6 m/s without losses)")
    expect.gt(moved, 0.3, "a block is knocked at least 0.3 m the ball's way")
    expect.eq(inside, 0, "no block particle inside the ball")
    -- undisturbed, 0.6 m past the bottom it is 0.10 m higher and keeps 97 % of its speed;
    -- the tower takes a good part of it (or stops it: then it never gets there)
    if after_speed < math.huge then expect.lt(after_speed, 0.8 * hit_speed, "the tower slows the ball") end
  end)
end
