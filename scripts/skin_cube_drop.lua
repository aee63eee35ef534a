-- skin_cube_drop.lua: the reference thesis's skinned cube (its Figures 14 and 15). A
-- high-poly rounded cube (assets/rounded_cube.obj, 6146 vertices) is bound by linear blend
-- skinning to a coarse 4x4x4 cage of particles and dropped, tilted, on the ground. The
-- solver moves 64 particles; the mesh follows them, flattening on impact and rounding out
-- again, each vertex blended from its 4 nearest particles and their rotations.
-- Run:     build/wobble run scripts/skin_cube_drop.lua
-- Export:  build/wobble run scripts/skin_cube_drop.lua --set export=1
--          out/skin_cube_drop.pc2 + .obj (Blender: import the .obj, Mesh Cache modifier on the .pc2)
--          out/skin_cube_drop.pvd (ParaView: paraview out/skin_cube_drop.pvd)
-- Options: --set res=5 (cage particles per axis), --set compliance=1e-3 (softer), --set height=2,
--          --set seconds=5
local args = wobble.args
local res = args.res or 4
local w = wobble.world{ substeps = 20 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.6, restitution = 0.1 }

-- the mesh (relative to this file's folder) and its cage, both around the origin; the
-- cage's particles are 5 cm balls 0.45 m out, so its faces touch the ground where the
-- mesh's faces would (the rounded corners sit a little inside the cage's)
local mesh = assert(wobble.load_mesh("../assets/rounded_cube.obj"))
local cage = w:lattice{ min = {-0.45, -0.45, -0.45}, max = {0.45, 0.45, 0.45}, res = {res, res, res}, mass = 2,
                        radius = 0.05, compliance = args.compliance or 1e-4, damping = 0.02 }
local skin = w:skin(mesh, cage, { bones = 4 })

-- tilt the cage 25 degrees about (1, 0, 1) and lift it: the skin follows from its bind pose
local a, k = math.rad(25), 1 / math.sqrt(2)
local c, s = math.cos(a), math.sin(a)
local R = { { c + k * k * (1 - c), -k * s, k * k * (1 - c) },
            { k * s, c, -k * s },
            { k * k * (1 - c), k * s, c + k * k * (1 - c) } }
for _, p in ipairs(cage.particles) do
  local x, y, z = w:position(p)
  w:set_position(p, R[1][1] * x + R[1][2] * y + R[1][3] * z,
                    R[2][1] * x + R[2][2] * y + R[2][3] * z + (args.height or 1.1),
                    R[3][1] * x + R[3][2] * y + R[3][3] * z)
end

local recorders = {}
if args.export then
  recorders[1] = assert(skin:record_pc2("skin_cube_drop.pc2"))
  recorders[2] = assert(w:record_vtk("skin_cube_drop"))
end

local landed, settled, deepest = nil, nil, 0
w:run{ seconds = args.seconds or 3, on_frame = function(w, f)
  if not landed and select(2, w:bounds()) < 0.06 then landed = f end
  local _, y0 = skin:bounds()
  deepest = math.min(deepest, y0)
  local kinetic = w:energy()
  if landed and not settled and kinetic < 1e-4 then settled = f end
  if settled and kinetic > 1e-3 then settled = nil end
end }
for _, r in ipairs(recorders) do r:close() end

local x0, y0, z0, x1, y1, z1 = skin:bounds()
print(string.format("skinned cube: %d vertices on %d particles; lands at frame %s, settles at frame %s, "
                    .. "rests %.3f x %.3f x %.3f m; its lowest vertex went %.1f mm into the ground",
                    skin:vertex_count(), #cage.particles, tostring(landed), tostring(settled), x1 - x0, y1 - y0,
                    z1 - z0, -1000 * deepest))
