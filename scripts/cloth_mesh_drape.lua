-- cloth_mesh_drape.lua: a cloth dropped over an imported mesh collider (the rounded
-- cube of assets/rounded_cube.obj, loaded through wobble.load_mesh) drapes over it: the
-- sheet comes to rest on the cube's top, its sides hang down the faces, and no particle
-- ends inside the mesh (the collider's signed distance is negative inside). Try
-- --set mesh=torus for the torus of assets/torus.ply, held up on a post.
-- Run: build/wobble run scripts/cloth_mesh_drape.lua
--      build/wobble test scripts/cloth_mesh_drape.lua   (runs it and checks the drape)
local args = wobble.args
local w = wobble.world{ substeps = 20 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
local col, top
if args.mesh == "torus" then
  -- the torus lies in the xz plane, 2 m across and 0.6 m thick at scale 2: its top at y = 0.9
  col = w:collider{ shape = "mesh", mesh = wobble.load_mesh("../assets/torus.ply"), scale = 2,
                    center = {0, 0.6, 0}, friction = 0.5 }
  w:collider{ shape = "capsule", a = {0, 0, 0}, b = {0, 0.6, 0}, radius = 0.1, friction = 0.5 }
  top = 0.9
else
  -- the rounded cube spans -0.5..0.5: scaled by 1.2 and lifted, its top is at y = 1.2
  col = w:collider{ shape = "mesh", mesh = wobble.load_mesh("../assets/rounded_cube.obj"), scale = 1.2,
                    center = {0, 0.6, 0}, rotation = {math.cos(0.2), 0, math.sin(0.2), 0},
                    friction = args.friction or 0.5 }
  top = 1.2
end
local cloth = w:cloth{ origin = {-1.1, top + 0.3, -1.1}, size = {2.2, 2.2}, res = {36, 36},
                       compliance = 1e-6, bend = 100 }

-- the cloth's centre: the particle nearest the middle of the sheet
local centre, best = nil, math.huge
for _, p in ipairs(cloth.particles) do
  local x, _, z = w:position(p)
  if x * x + z * z < best then centre, best = p, x * x + z * z end
end

w:run{ seconds = args.seconds or 3, on_frame = function(w, f)
  if f % 60 == 0 then print(f, w:bounds()) end
end }

-- how deep the deepest particle is in the mesh (its distance minus its radius: >= 0
-- when none penetrates), where the centre rests, how far the sides hang
local worst, lowest = math.huge, math.huge
for _, p in ipairs(cloth.particles) do
  local x, y, z = w:position(p)
  worst = math.min(worst, col:distance(x, y, z) - w:radius(p))
  lowest = math.min(lowest, y)
end
local x, y, z = w:position(centre)
print(string.format("cloth centre at (%.3f, %.3f, %.3f), %.4f m above the mesh; deepest particle %.2e m; lowest %.2f m",
  x, y, z, col:distance(x, y, z), worst, lowest))

if test then  -- under `wobble test`: the header's claim
  test("the cloth drapes over the mesh: its centre rests on the top, no particle inside", function()
    expect.lt(math.sqrt(x * x + z * z), 0.1, "the centre is over the mesh")
    expect.near(y, top + w:radius(centre), 0.01, "the centre lies on the mesh's top")
    expect.gt(worst, -1e-3, "no particle deeper than 1 mm in the mesh")
    local vx, vy, vz = w:velocity(centre)
    expect.lt(math.sqrt(vx * vx + vy * vy + vz * vz), 0.05, "the centre is at rest")
    expect.lt(lowest, top - 0.3, "the sides hang down")
  end)
end
