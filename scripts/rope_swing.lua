-- rope_swing.lua: a rope pinned at one end swings down and wraps around a post.
-- Run: build/wobble run scripts/rope_swing.lua [--set segments=60]
local w = wobble.world{ substeps = 30 }
local rope = w:rope{ from = {-1, 2, 0}, to = {1, 2, 0}, segments = wobble.args.segments or 40,
                     mass = 0.5, radius = 0.02 }
w:pin(rope.particles[1])
w:collider{ shape = "capsule", a = {0.3, 0, -0.5}, b = {0.3, 1.4, 0.5}, radius = 0.08, friction = 0.3 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
w:run{ seconds = wobble.args.seconds or 4 }
local x, y, z = w:position(rope.particles[#rope.particles])
print(string.format("rope: %d segments; free end at (%.2f, %.2f, %.2f), max strain %.2f%%",
  #rope.particles - 1, x, y, z, 100 * w:max_strain()))
