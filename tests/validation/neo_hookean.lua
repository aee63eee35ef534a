-- neo_hookean.lua: Neo-Hookean tetrahedra (core/tet.c; Macklin & Müller 2021).
--
-- Hanging bar: a 1 m bar of 0.1 x 0.1 m section (A = 0.01 m^2), 1 kg, E = 1e5 Pa,
-- nu = 0.3, pinned by its top face, hangs under its own weight. Linear elasticity: it
-- stretches M g L / (2 E A) = 4.9 mm (strain 4.9e-3 at the top, small) and at mid-height
-- (axial strain M g / (2 E A)) narrows by nu times that. Lattice 3 x 21 x 3 particles, 480
-- tets, no links (young given): the tets alone hold it. 40 substeps x 1 iteration with
-- drag 5/s for 4 s settle it (the coupled 2x2 solve of each tet's two constraints keeps
-- the rest state a fixed point, so one iteration converges here: the XPBD stiffness ratio
-- w|grad C|^2 / (alpha/h^2) is ~0.1). Measured: stretch 1.3% over the theory (the pinned
-- top face cannot narrow: a stiffer top, and the coarse mesh), asked within 4%; lateral
-- strain measured ~0.8-0.95 of nu x axial (the Kuhn split is anisotropic and the mesh one
-- cell thick at the faces' middle), asked within 30%: it tells nu = 0.3 from 0 and 0.45.
-- Without the projection the bar falls away (stretch >> 1 m): the test fails.
--
-- Inverted / flat: a tet whose apex is pushed through its base (det F = -1) or onto it
-- (det F = 0) returns to det F = 1 (the hydrostatic constraint's gradient, the cofactor,
-- is never zero for a flat tet). Measured 1e-6 off after 2 s; asked 1e-3.
--
-- Energy: w:energy()'s potential at a known stretch diag(s1, s2, s3) of one tet equals
-- V0 [mu/2 (tr F^T F - 3) + lam/2 (det F - a)^2 - mu^2 / (2 lam)], a = 1 + mu/lam, with
-- mu = E / 2(1+nu) and lam = (Lamé lambda) + mu (the constraint form's remapping, see
-- tet.c); 0 at rest. Round-off only: asked 1e-9 relative.

local E, NU = 1e5, 0.3

local function bar(nu, young)
  local w = wobble.world{ gravity = { 0, -9.81, 0 }, substeps = 40, iterations = 1, damping = 5 }
  local nx, ny = 3, 21
  local b = w:lattice{ min = { -0.05, -1, -0.05 }, max = { 0.05, 0, 0.05 }, res = { nx, ny, nx }, mass = 1,
                       tets = true, young = young or E, poisson = nu, collide = false }
  local function P(i, j, k) return b.first + i + (j + k * ny) * nx end
  for k = 0, nx - 1 do for i = 0, nx - 1 do w:pin(P(i, ny - 1, k)) end end
  for _ = 1, 240 do w:step() end
  local bottom, n = 0, 0
  for k = 0, nx - 1 do for i = 0, nx - 1 do
    local _, y = w:position(P(i, 0, k)); bottom = bottom + y; n = n + 1
  end end
  -- mid-height width in x and z: the mean of the side layers' coordinates
  local mid, wx, wz = (ny - 1) // 2, 0, 0
  for k = 0, nx - 1 do
    wx = wx + (w:position(P(nx - 1, mid, k)) - w:position(P(0, mid, k))) / nx
    local _, _, z1 = w:position(P(k, mid, nx - 1))
    local _, _, z0 = w:position(P(k, mid, 0))
    wz = wz + (z1 - z0) / nx
  end
  return w, b, -1 - bottom / n, ((wx + wz) / 2 - 0.1) / 0.1
end

test("a bar hanging under its own weight stretches M g L / (2 E A) and narrows by nu", function()
  local w, b, stretch, lateral = bar(NU)
  expect.eq(w:tet_count(), 6 * 2 * 20 * 2, "6 tets per cell")
  expect.eq(b.tet_count, w:tet_count(), "body.tet_count")
  expect.eq(w:volume_count(), 0, "Neo-Hookean tets instead of volume constraints")
  expect.eq(b.constraint_count, 0, "no links: the tets alone")
  local theory = 1 * 9.81 * 1 / (2 * E * 0.01)
  expect.near(stretch / theory, 1, 0.04, "stretch / (M g L / 2 E A)")
  local axial = 9.81 * 0.5 / (E * 0.01) -- strain at mid-height
  expect.near(-lateral / (NU * axial), 1, 0.3, "lateral strain / (nu x axial strain)")
  local _, _, _, lateral0 = bar(0)
  expect.lt(math.abs(lateral0), 0.3 * NU * axial, "nu = 0: hardly narrows")
end)

local function one_tet(opts)
  local w = wobble.world{ gravity = { 0, 0, 0 }, substeps = 20, iterations = 1 }
  local p = {}
  for i, x in ipairs{ { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } } do
    p[i] = w:particle{ pos = x, mass = 1 }
  end
  return w, p, w:tet(p[1], p[2], p[3], p[4], opts)
end

test("an inverted or flattened tet recovers its rest volume", function()
  for _, apex in ipairs{ -1, 0 } do
    local w, p, t = one_tet{ young = E, poisson = NU }
    w:set_position(p[4], 0.1, 0.1, apex)
    local j0 = w:tet_info(t)
    expect.near(j0, apex, 1e-12, "det F as set")
    for _ = 1, 120 do w:step() end
    local j, _, v0 = w:tet_info(t)
    expect.near(v0, 1 / 6, 1e-15, "rest volume")
    expect.near(j, 1, 1e-3, "det F back to 1 from " .. apex)
  end
end)

test("energy at a known stretch is the stable Neo-Hookean energy", function()
  local w, p, t = one_tet{ young = E, poisson = NU }
  local _, pe0 = w:energy()
  expect.near(pe0, 0, 1e-9, "no energy at rest")
  local s = { 1.1, 0.95, 1.02 }
  w:set_position(p[2], s[1], 0, 0)
  w:set_position(p[3], 0, s[2], 0)
  w:set_position(p[4], 0, 0, s[3])
  local mu = E / (2 * (1 + NU))
  local lam = E * NU / ((1 + NU) * (1 - 2 * NU)) + mu
  local a, J = 1 + mu / lam, s[1] * s[2] * s[3]
  local ic = s[1] ^ 2 + s[2] ^ 2 + s[3] ^ 2
  local psi = (mu / 2 * (ic - 3) + lam / 2 * (J - a) ^ 2 - mu * mu / (2 * lam)) / 6
  local _, pe = w:energy()
  expect.near(pe / psi, 1, 1e-9, "w:energy() = V0 Psi(F)")
  local jj, e = w:tet_info(t)
  expect.near(jj, J, 1e-12, "tet_info: det F")
  expect.near(e, pe, 1e-9 * psi, "tet_info: energy")
end)

test("w:tet checks its arguments", function()
  local w = wobble.world{}
  local p = {}
  for i = 1, 4 do p[i] = w:particle{ pos = { i, 0, 0 } } end
  expect.error(function() w:tet(p[1], p[2], p[3], p[4]) end, "plane")
  expect.error(function() w:tet(p[1], p[1], p[3], p[4]) end, "distinct")
  expect.error(function() w:tet(p[1], p[2], p[3], p[4], { poisson = 0.5 }) end, "poisson")
  expect.error(function() w:tet(p[1], p[2], p[3], p[4], { young = 0 }) end, "young")
  expect.error(function() w:lattice{ young = 1e5 } end, "tets")
end)
