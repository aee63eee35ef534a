-- mesh_torus_drop.lua: a particle graph made from a mesh (the reference thesis's first
-- import method). A high-poly torus (assets/torus.ply, 6144 vertices) becomes a coarse cage
-- of about 150 particles by vertex clustering, braced by soft links to each particle's
-- nearest neighbours and filled like an inflatable ring (w:pressure keeps the volume of the
-- cage's closed surface, so its tube does not collapse while its ring bends); the full
-- torus is skinned to that cage. It drops onto a ball, sags over it (bends out of its
-- plane by a fifth), slides off onto the ground and lies there round again.
-- Run:     build/wobble run scripts/mesh_torus_drop.lua [--record out/torus/]
-- Options: --set target=300 (cage particles), --set compliance=2e-4 (stiff: it lands on the
--          ball rigidly and slides off), --set pressure=0 (no air: its tube caves in),
--          --set seconds=5, --set export=1 (out/mesh_torus_drop.pc2 + .obj for Blender's
--          Mesh Cache modifier)
local args = wobble.args
local w = wobble.world{ substeps = 20 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
local ball = w:collider{ shape = "sphere", center = {0.1, 0.35, 0}, radius = 0.35, friction = 0.3 }

-- the camera `--record` draws with and `wobble view` starts with: from the front and above,
-- across the way it slides off, so that its bend over the ball shows
wobble.camera{ eye = {-0.1, 1.7, 3.3}, target = {-0.3, 0.55, 0} }

local torus = assert(wobble.load_mesh("../assets/torus.ply")) -- relative to this file's folder
torus:transform{ translate = {0, 1.2, 0} }
local cage = w:from_mesh(torus, { target = args.target or 150, neighbours = args.neighbours or 10, mass = 1,
                                  compliance = args.compliance or 8e-2, damping = 0.05, radius = 0.01 })
if (args.pressure or 1) > 0 then w:pressure(cage, { pressure = args.pressure or 1 }) end
local skin = w:skin(torus, cage, { bones = 4 })
local rec = args.export and assert(skin:record_pc2("mesh_torus_drop.pc2"))

-- how far the cage is from flat: the RMS distance of its particles from their best-fit
-- plane, the square root of the smallest eigenvalue of their covariance (closed form for
-- a symmetric 3x3, O. K. Smith 1961); it does not change when the torus turns or tilts
local function out_of_plane()
  local ids, n = cage.particles, #cage.particles
  local mx, my, mz = 0, 0, 0
  for _, p in ipairs(ids) do
    local x, y, z = w:position(p)
    mx, my, mz = mx + x, my + y, mz + z
  end
  mx, my, mz = mx / n, my / n, mz / n
  local a, b, c, d, e, f = 0, 0, 0, 0, 0, 0 -- xx, yy, zz, xy, xz, yz
  for _, p in ipairs(ids) do
    local x, y, z = w:position(p)
    x, y, z = x - mx, y - my, z - mz
    a, b, c, d, e, f = a + x * x, b + y * y, c + z * z, d + x * y, e + x * z, f + y * z
  end
  a, b, c, d, e, f = a / n, b / n, c / n, d / n, e / n, f / n
  local q = (a + b + c) / 3
  local p = math.sqrt(((a - q) ^ 2 + (b - q) ^ 2 + (c - q) ^ 2 + 2 * (d * d + e * e + f * f)) / 6)
  if p == 0 then return math.sqrt(math.max(q, 0)) end
  local A, B, C, D, E, F = (a - q) / p, (b - q) / p, (c - q) / p, d / p, e / p, f / p
  local det = A * (B * C - F * F) - D * (D * C - F * E) + E * (D * F - B * E)
  local phi = math.acos(math.max(-1, math.min(1, det / 2))) / 3
  return math.sqrt(math.max(q + 2 * p * math.cos(phi + 2 * math.pi / 3), 0))
end
local flat0 = out_of_plane()
local on_ball = function()  -- some particle touching the ball
  for _, p in ipairs(cage.particles) do
    if ball:distance(w:position(p)) < 0.02 then return true end
  end
  return false
end

local sag = 1 -- the most the cage was bent out of its plane while on the ball, / at rest
w:run{ seconds = args.seconds or 4, on_frame = function(w)
  if on_ball() then sag = math.max(sag, out_of_plane() / flat0) end
end }
if rec then rec:close() end
local x0, y0, z0, x1, y1, z1 = skin:bounds()
local flat_end = out_of_plane() / flat0
print(string.format("torus: %d vertices skinned to %d particles (%d links); bent out of its plane %.2f x on the ball; "
                    .. "rests %.2f x %.2f x %.2f m (%.2f x its rest flatness), lowest vertex at %.3f m",
                    skin:vertex_count(), cage.count, cage.constraint_count, sag, x1 - x0, y1 - y0, z1 - z0, flat_end, y0))

if test then  -- under `wobble test`: the header's claim
  test("the torus sags over the ball, slides off and lies round on the ground", function()
    -- a rigid torus stays at 1.00 (measured 1.00 with compliance 2e-4, the old default);
    -- this one bends out of its plane by a fifth while it touches the ball (measured 1.21)
    expect.gt(sag, 1.15, "sagged over the ball")
    expect.lt(y1, 0.35, "off the ball, lying flat (its tube is 0.29 m thick)")
    expect.near(y0, 0, 0.02, "on the ground")
    -- round again, flattened a little by its weight on the soft links (measured 0.91 of
    -- its rest flatness and 1.05 m wide); a crumpled one (no pressure) ends at 0.6-0.7
    expect.near(flat_end, 1, 0.15, "round again: its flatness back within 15%")
    expect.near(x1 - x0, 0.96, 0.12, "its width back within 12% of the mesh's 0.96 m")
  end)
end
