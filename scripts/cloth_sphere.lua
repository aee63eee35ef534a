-- cloth_sphere.lua: a cloth pinned along one edge drapes over a sphere onto the ground.
-- Run: build/wobble run scripts/cloth_sphere.lua
local w = wobble.world{ substeps = 20 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
w:collider{ shape = "sphere", center = {0, 0.5, 0}, radius = 0.4 }
local cloth = w:cloth{ origin = {-1, 1.5, -1}, size = {2, 2}, res = {30, 30}, compliance = 1e-6 }
cloth:pin_where(function(x, y, z) return z < -0.99 end)
w:run{ seconds = wobble.args.seconds or 3, on_frame = function(w, f)
  if f % 60 == 0 then print(f, w:bounds()) end
end }
