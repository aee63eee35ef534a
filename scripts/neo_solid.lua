-- neo_solid.lua: a Neo-Hookean solid from a mesh. The rounded cube (assets/rounded_cube.obj)
-- is filled with tetrahedra by tetgen and each tet is a stable Neo-Hookean element
-- (Macklin & Müller 2021; w:tet): Young's modulus E and Poisson's ratio nu, no links. It
-- drops onto the ground, squashes on impact and comes back to its shape: rubber-like
-- (E = 1e5 Pa here: soft enough to see it squash; 1000 kg/m^3), at 20 substeps: the
-- substep must stay below about twice the time a wave (speed sqrt(E / density)) takes to
-- cross the smallest tet, and the mesh's dense surface (6146 vertices, kept by tetgen)
-- makes small tets (at 10 substeps the world warns and asks for about 19). A stiffer one:
-- --set young=1e6 --set substeps=60.
-- Run: build/wobble run scripts/neo_solid.lua [--set young=1e5] [--set poisson=0.45]
local args = wobble.args
local w = wobble.world{ substeps = args.substeps or 20, iterations = 1 }
w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, friction = 0.6 }
local m = assert(wobble.load_mesh("../assets/rounded_cube.obj")) -- relative to this file's folder
local x0, y0, z0, x1, y1, z1 = m:bounds()
m:transform{ translate = { -(x0 + x1) / 2, 0.8 - y0, -(z0 + z1) / 2 } }
local solid = w:from_mesh(m, { tets = true, max_volume = 0.01, mass = 1000, young = args.young or 1e5,
                               poisson = args.poisson or 0.4, radius = 0.01 })
local h0 = y1 - y0
local lowest, inverted = math.huge, 0
w:run{ seconds = args.seconds or 2.5, on_frame = function(w)
  local _, miny, _, _, maxy = w:bounds()
  if miny < 0.05 then lowest = math.min(lowest, maxy - miny) end
end }
for i = 1, w:tet_count() do
  if w:tet_info(i) <= 0 then inverted = inverted + 1 end
end
local _, miny, _, _, maxy = w:bounds()
print(string.format("neo solid: %d particles, %d tets, %.2f m tall; squashed to %.2f m on impact, rests %.2f m tall, "
  .. "%d inverted tets", solid.count, solid.tet_count, h0, lowest, maxy - miny, inverted))

if test then
  test("the Neo-Hookean solid lands, squashes and comes back to its shape", function()
    expect.eq(solid.constraint_count, 0, "no links: the tets alone hold it")
    expect.gt(solid.tet_count, 50, "filled with tets")
    expect.lt(lowest, 0.98 * h0, "squashed on impact")
    expect.near((maxy - miny) / h0, 1, 0.05, "back to its height (sagging a little under its weight)")
    expect.lt(miny, 0.05, "resting on the ground")
    expect.eq(inverted, 0, "no tet left inverted")
    expect.eq((w:warnings()), 0, "no warning: the substep is within the tets' wave time")
  end)
end
