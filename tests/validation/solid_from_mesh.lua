-- solid_from_mesh.lua: w:from_mesh(m, {tets = true}) with every default fills a coarse
-- closed mesh with a resolved solid (lua/mesh.c: max_volume defaults to a thousandth of
-- the enclosed volume; tetgen may split the mesh's triangles when keeping them would
-- leave the bound unmet).
--
-- The coarsest closed mesh, assets/cube.obj (8 corners, 12 triangles, 1 m across):
--  - filled: particles strictly inside (more than a tenth of the side from every face);
--    a few hundred to a few thousand in all. Before, tetgen kept the 12 triangles and
--    the body was 9 particles and 12 tets with no interior: this test failed.
--  - the tets tile the cube: their rest volumes add up to the enclosed 1 m^3. tetgen
--    writes its points with 16 significant digits, so the sum is exact to round-off:
--    asked 1e-9 relative.
--  - every tet within the default bound (1 litre; tetgen rounds: 0.1 %).
--  - a solid under gravity: E = 1e5 Pa, nu = 0.3, 1000 kg, resting on a frictionless
--    floor (so its sides bulge freely: uniaxial stress). Linear elasticity: the stress
--    at depth s is rho g s, the strain rho g s / E, and the height shrinks by
--    rho g H^2 / (2 E) = 4.9 cm, the volume by (1 - 2 nu) times that strain: 2%.
--    Measured 6% under it; asked within 10% (1 iteration per substep does not converge the
--    stiffness fully on 2,400 tets, and a Neo-Hookean block is not quite linear at 10%
--    strain at its base), and the body's volume within 1% of (1 - (1 - 2 nu) sag / H).
--    A block with no interior (the 12 tets) has no layers to carry that stress.
--  - a skin over it binds: the mesh's own vertices, skinned to the solid's particles,
--    start where they are and follow the block down.

local function cube_mesh() return assert(wobble.load_mesh("../../assets/cube.obj")) end

test("tets = true on a cube of 8 corners: a filled solid whose tets tile it", function()
  local m = cube_mesh()
  expect.eq(m:vertex_count(), 8)
  local w = wobble.world{}
  local b = w:from_mesh(m, { tets = true })
  local inside = 0
  for _, p in ipairs(b.particles) do
    local x, y, z = w:position(p)
    local d = math.min(0.5 - math.abs(x), 0.5 - math.abs(y), 0.5 - math.abs(z))
    if d > 0.1 then inside = inside + 1 end
  end
  print(string.format("# %d particles, %d inside, %d tets", b.count, inside, b.tet_count))
  expect.gt(inside, 20, "particles inside, away from the faces")
  expect.gt(b.count, 200, "a few hundred particles at least")
  expect.lt(b.count, 5000, "a few thousand at most")
  local total, big = 0, 0
  for i = 1, w:volume_count() do
    local _, v0 = w:volume_info(i)
    total = total + v0
    big = math.max(big, v0)
  end
  expect.rel(total, 1, 1e-9, "the tets' volume is the cube's")
  expect.le(big, 1e-3 * 1.001, "every tet within the default bound")
  -- the bound scales with the mesh: the same count at 10 cm
  local m2 = cube_mesh()
  m2:transform{ scale = 0.1 }
  local b2 = wobble.world{}:from_mesh(m2, { tets = true })
  expect.near(b2.count / b.count, 1, 0.2, "the default resolution does not depend on the scale")
end)

test("the filled cube rests on the floor as a solid: it sags rho g H^2 / 2E and keeps its volume", function()
  local E, NU, RHO, G = 1e5, 0.3, 1000, 9.81
  local w = wobble.world{ gravity = { 0, -G, 0 }, substeps = 20, damping = 4 }
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0 }
  local m = cube_mesh()
  local r = 0.02 -- the radius asked: the block made resting at y = r
  m:transform{ translate = { 0, 0.5 + r, 0 } }
  local b = w:from_mesh(m, { tets = true, mass = RHO, young = E, poisson = NU, radius = r })
  expect.eq(w:tet_count(), b.tet_count, "Neo-Hookean tets")
  -- the skin: the mesh's 8 corners over the solid
  local s = w:skin(m, b)
  for i = 1, 8 do
    local x, y, z = m:vertex(i)
    local u, v, q = s:vertex(i)
    expect.near(u, x, 1e-9); expect.near(v, y, 1e-9); expect.near(q, z, 1e-9)
  end
  local function layer(top)
    local sum, n = 0, 0
    for _, p in ipairs(b.particles) do
      local _, y = w:position(p)
      sum, n = sum + y, n + 1
    end
    local mean = sum / n
    local ysum, k = 0, 0
    for _, p in ipairs(b.particles) do
      local _, y = w:position(p)
      if (top and y > mean + 0.45) or (not top and y < mean - 0.45) then ysum, k = ysum + y, k + 1 end
    end
    return ysum / k, k
  end
  local t0, nt = layer(true)
  local b0, nb = layer(false)
  expect.gt(nt, 20); expect.gt(nb, 20)
  w:run{ seconds = 4 }
  local h = layer(true) - layer(false)
  local sag = (t0 - b0) - h
  local theory = RHO * G * 1 / (2 * E)
  local vol = 0
  for i = 1, w:tet_count() do
    local j, _, v0 = w:tet_info(i)
    vol = vol + j * v0
  end
  print(string.format("# sag %.4f m (theory %.4f), volume %.4f (linear %.4f), warnings %d", sag, theory, vol,
                      1 - (1 - 2 * NU) * theory, (w:warnings())))
  expect.near(sag / theory, 1, 0.1, "sag / (rho g H^2 / 2E)")
  expect.near(vol, 1 - (1 - 2 * NU) * theory, 0.01, "volume")
  local _, miny = w:bounds()
  expect.near(miny, r, 1e-3, "resting on the floor (its lowest particles at y = r)")
  -- the skin followed: its top corners came down with the block's top
  local _, ytop = s:vertex(7)
  expect.near(ytop, layer(true), 0.02, "the skin's top corner with the block's top")
  expect.eq((w:warnings()), 0, "no warning")
end)
