-- mesh_torus_drop.lua: a particle graph made from a mesh (the reference thesis's first
-- import method). A high-poly torus (assets/torus.ply, 6144 vertices) becomes a coarse cage
-- of about 150 particles by vertex clustering, braced by links to each particle's nearest
-- neighbours; the full torus is skinned to that cage. It drops onto a ball, sags over it
-- and slides off onto the ground.
-- Run:     build/wobble run scripts/mesh_torus_drop.lua
-- Options: --set target=300 (cage particles), --set compliance=1e-3 (softer), --set seconds=5
--          --set export=1 (out/mesh_torus_drop.pc2 + .obj for Blender's Mesh Cache modifier)
local args = wobble.args
local w = wobble.world{ substeps = 20 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
w:collider{ shape = "sphere", center = {0.15, 0.35, 0}, radius = 0.35, friction = 0.3 }

local torus = assert(wobble.load_mesh("../assets/torus.ply")) -- relative to this file's folder
torus:transform{ translate = {0, 1.2, 0} }
local cage = w:from_mesh(torus, { target = args.target or 150, neighbours = 10, mass = 1,
                                  compliance = args.compliance or 2e-4, damping = 0.05, radius = 0.01 })
local skin = w:skin(torus, cage, { bones = 4 })
local rec = args.export and assert(skin:record_pc2("mesh_torus_drop.pc2"))

local lowest_top = math.huge
w:run{ seconds = args.seconds or 3, on_frame = function(w)
  local _, _, _, _, top = skin:bounds()
  lowest_top = math.min(lowest_top, top)
end }
if rec then rec:close() end
local x0, y0, z0, x1, y1, z1 = skin:bounds()
print(string.format("torus: %d vertices skinned to %d particles (%d links); top came down to %.3f m; "
                    .. "rests %.2f x %.2f x %.2f m, lowest vertex at %.3f m",
                    skin:vertex_count(), cage.count, cage.constraint_count, lowest_top, x1 - x0, y1 - y0, z1 - z0, y0))
