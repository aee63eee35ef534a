-- rope_swing.lua: a rope pinned at one end swings down, catches on a horizontal post (a
-- peg on an upright) and wraps around it: the part past the post whips round it more
-- than a full turn, and friction keeps it wound.
-- Run: build/wobble run scripts/rope_swing.lua [--set segments=60]
--      build/wobble test scripts/rope_swing.lua   (runs it and checks that it wraps)
local args = wobble.args
local w = wobble.world{ substeps = 30 }
local rope = w:rope{ from = {-1, 2, 0}, to = {1, 2, 0}, segments = args.segments or 40,
                     mass = 0.5, radius = 0.02 }
w:pin(rope.particles[1])
-- the post: across the rope's swing (along z), 1.3 m from the pin, so the rope's last
-- 0.7 m swing past it; thick enough that no link of the rope slips through it
local post_a, post_b = {0, 1.2, -0.5}, {0, 1.2, 0.5}
w:collider{ shape = "capsule", a = post_a, b = post_b, radius = 0.05, friction = 0.3 }
w:collider{ shape = "capsule", a = {0, 0, -0.5}, b = post_a, radius = 0.05 }  -- the upright
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }

-- the angle the free end sweeps around the post's axis, frame by frame
local function sub(a, b) return { a[1] - b[1], a[2] - b[2], a[3] - b[3] } end
local function dot(a, b) return a[1] * b[1] + a[2] * b[2] + a[3] * b[3] end
local function cross(a, b) return { a[2] * b[3] - a[3] * b[2], a[3] * b[1] - a[1] * b[3], a[1] * b[2] - a[2] * b[1] } end
local axis = sub(post_b, post_a)
local len = math.sqrt(dot(axis, axis))
axis = { axis[1] / len, axis[2] / len, axis[3] / len }
local e1 = cross(axis, math.abs(axis[1]) < 0.9 and {1, 0, 0} or {0, 1, 0})
local e2 = cross(axis, e1)
local tip = rope.particles[#rope.particles]
local function angle()
  local r = sub({ w:position(tip) }, post_a)
  return math.atan(dot(r, e2), dot(r, e1))
end
local last, swept = angle(), 0
w:run{ seconds = args.seconds or 4, on_frame = function()
  local a = angle()
  swept = swept + (a - last + math.pi) % (2 * math.pi) - math.pi  -- the step, unwrapped
  last = a
end }

local x, y, z = w:position(tip)
local turns = math.abs(swept) / (2 * math.pi)
print(string.format("rope: %d segments; free end at (%.2f, %.2f, %.2f), wound %.2f turns around the post, "
  .. "max strain %.2f%%", #rope.particles - 1, x, y, z, turns, 100 * w:max_strain()))

if test then  -- under `wobble test`: the header's claim
  test("the rope wraps around the post: its free end sweeps more than a full turn", function()
    expect.gt(turns, 1, "turns of the free end around the post's axis")
    local r = sub({ x, y, z }, post_a)
    local along = dot(r, axis)
    local d = math.sqrt(dot(r, r) - along * along)
    expect.lt(d, 0.3, "the free end stays close to the post, wound on it")
  end)
end
