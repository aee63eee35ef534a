-- cantilever.lua: a Neo-Hookean cantilever under its own weight against Euler-Bernoulli.
--
-- A beam of length L, square section a x a, clamped at x = 0 (its first layer of
-- particles pinned), loaded by its weight q = M g / L, bends at its tip by
--   w_tip = q L^4 / (8 E I),   I = a^4 / 12      (Euler-Bernoulli, small deflection).
-- Linear tetrahedra are known to be too stiff in bending ("shear locking"): a coarse mesh
-- deflects a fraction of that, and the fraction grows towards 1 as the mesh is refined,
-- the faster the more elements span the section. The test checks exactly that: the tip
-- deflection grows with each refinement, stays below the beam-theory value (a mesh that
-- overshot would be softer than the continuum: wrong), and the finest mesh gets within
-- 40% of it (measured: 0.38, 0.60, 0.71 of w_tip for the three meshes).
-- L/a = 10 makes Euler-Bernoulli apply (shear deflection ~ (a/L)^2 of the bending one)
-- and w_tip / L ~ 1.5% keeps it in small deflection. 120 frames with damping settle it.

local E, NU, L, A, M, G = 1e7, 0.3, 1, 0.1, 1, 9.81

local function tip(nx, nt, substeps)
  local w = wobble.world{ gravity = {0, -G, 0}, substeps = substeps, iterations = 1, damping = 8 }
  local b = w:lattice{ min = {0, -A / 2, -A / 2}, max = {L, A / 2, A / 2}, res = {nx, nt, nt}, mass = M,
                       tets = true, young = E, poisson = NU, collide = false }
  local function P(i, j, k) return b.first + i + (j + k * nt) * nx end
  for k = 0, nt - 1 do for j = 0, nt - 1 do w:pin(P(0, j, k)) end end
  w:run{ frames = 120 }
  expect.eq(w:warnings(), 0, "no numerical trouble")
  local s = 0
  for k = 0, nt - 1 do for j = 0, nt - 1 do local _, y = w:position(P(nx - 1, j, k)); s = s + y end end
  return -s / (nt * nt)
end

test("a Neo-Hookean cantilever's tip deflection approaches Euler-Bernoulli as the mesh is refined", function()
  local I = A ^ 4 / 12
  local eb = (M * G / L) * L ^ 4 / (8 * E * I)
  local coarse, longer, finer = tip(11, 3, 120), tip(21, 3, 120), tip(21, 5, 200)
  print(string.format("tip / Euler-Bernoulli: %.3f, %.3f, %.3f", coarse / eb, longer / eb, finer / eb))
  expect.gt(coarse, 0, "the beam bends down")
  expect.gt(longer, coarse * 1.1, "more elements along the beam: closer to beam theory")
  expect.gt(finer, longer * 1.1, "more elements across the section: closer still")
  expect.lt(finer, eb, "never softer than the continuum")
  expect.gt(finer, 0.6 * eb, "the finest mesh within 40% of Euler-Bernoulli")
end)
