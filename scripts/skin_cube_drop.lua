-- skin_cube_drop.lua: the reference thesis's skinned cube (its Figures 14 and 15). A
-- high-poly rounded cube (assets/rounded_cube.obj, 6146 vertices) is bound by linear blend
-- skinning to a coarse 4x4x4 cage of particles and dropped, tilted, on the ground. The
-- solver moves 64 particles; the mesh follows them, flattening on impact and rounding out
-- again, each vertex blended from its 8 nearest particles and their rotations (a vertex
-- inside a cell of a regular lattice has 8 corners about equally near: with fewer bones
-- the choice among them flips from vertex to vertex and the skin shows seams).
-- Run:     build/wobble run scripts/skin_cube_drop.lua
--          build/wobble test scripts/skin_cube_drop.lua   (runs it and checks for seams)
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
local skin = w:skin(mesh, cage, { bones = args.bones or 8 })

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

-- under `wobble test`: the mesh's edges at rest, to measure how far the skin stretches
local edges, stretch = {}, 0
if test then
  local seen = {}
  for t = 1, mesh:triangle_count() do
    local v = { mesh:triangle(t) }
    for e = 1, 3 do
      local i, j = math.min(v[e], v[e % 3 + 1]), math.max(v[e], v[e % 3 + 1])
      if not seen[i * 65536 + j] then
        seen[i * 65536 + j] = true
        local x0, y0, z0 = mesh:vertex(i)
        local x1, y1, z1 = mesh:vertex(j)
        edges[#edges + 1] = { i, j, math.sqrt((x1 - x0) ^ 2 + (y1 - y0) ^ 2 + (z1 - z0) ^ 2) }
      end
    end
  end
end

local landed, settled, deepest, cage_strain = nil, nil, 0, 0
w:run{ seconds = args.seconds or 3, on_frame = function(w, f)
  cage_strain = math.max(cage_strain, w:max_strain())
  if #edges > 0 and f % 2 == 0 then  -- every other frame: the impact lasts many
    local v = {}
    for i = 1, skin:vertex_count() do v[i] = { skin:vertex(i) } end
    for _, e in ipairs(edges) do
      local a, b = v[e[1]], v[e[2]]
      local len = math.sqrt((b[1] - a[1]) ^ 2 + (b[2] - a[2]) ^ 2 + (b[3] - a[3]) ^ 2)
      stretch = math.max(stretch, math.abs(len / e[3] - 1))
    end
  end
  if not landed and select(2, w:bounds()) < 0.06 then landed = f end
  local _, y0 = skin:bounds()
  deepest = math.min(deepest, y0)
  local kinetic = w:energy()
  if landed and not settled and kinetic < 1e-4 then settled = f end
  if settled and kinetic > 1e-3 then settled = nil end
end }
for _, r in ipairs(recorders) do r:close() end

local x0, y0, z0, x1, y1, z1 = skin:bounds()
-- (a run too short to settle says so, rather than "settles at frame nil")
local settles = settled and string.format("settles at frame %d", settled)
                or string.format("still moving at the end (kinetic %.2g J)", w:energy())
print(string.format("skinned cube: %d vertices on %d particles; lands at frame %s, %s, "
                    .. "ends %.3f x %.3f x %.3f m; its lowest vertex went %.1f mm into the ground",
                    skin:vertex_count(), #cage.particles, tostring(landed), settles, x1 - x0, y1 - y0,
                    z1 - z0, -1000 * deepest))

if test then
  -- a smooth skin stretches no more than the cage that moves it; a seam (a vertex whose
  -- bones differ from its neighbour's) opens its edges further
  test("the skin follows its cage without seams: no mesh edge stretches more than the cage", function()
    expect.gt(cage_strain, 0.02, "the drop deforms the cage")
    expect.lt(stretch, cage_strain, "largest strain of a mesh edge, against the cage's largest")
  end)
end
