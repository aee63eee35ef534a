-- vbd_free_fall.lua: a body in free fall keeps the shape it was made with, in both solvers.
--
-- Uniform gravity deforms nothing: every particle of a free body moves by the same
-- x0 + n h v0 + h^2 g n (n + 1) / 2 (free_fall.lua's exact step), so each particle's
-- displacement less the body's mean is zero but for rounding. Three bodies a constraint
-- type each (a wavy hand-built chain of 80 rigid links, a cloth with shear links and
-- bends, a block of Neo-Hookean tets), thrown with a common velocity, fall for 1 s at 20
-- substeps; a ground plane far below and a box turning 10 m away are in the world, so the
-- solver's "no collider can reach it" is taken, not skipped.
--
-- Tolerance: twice free_fall.lua's round-off bound on one particle's position after n
-- substeps (two particles' errors in a difference), 2 (2 n eps |x| + h n 4 n eps (|x| / h
-- + |v|)) with |x| <= 10 m, |v| <= 15 m/s, n = 1200: 2.6e-8 m. Measured 3e-12 m for either
-- solver. VBD starting its sweeps from x + h v (the prediction less the gravity) bent the
-- chain 0.74 m, the cloth 0.1 mm and the block 5.6 um off their shapes.

local eps = 2.0 ^ -52
local N, T = 20, 1
local V0 = { 1, 2, -0.5 }

local function world(solver)
  local w = wobble.world{ solver = solver, substeps = N }
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = -200 }
  local box = w:collider{ shape = "box", center = { 12, 5, 0 }, half = { 0.5, 0.5, 0.5 } }
  box:set_angular_velocity(0, 0, 2)
  return w
end

-- each particle's displacement less the mean over the body, largest; and how far the mean
-- is from the exact free fall of the integrator (free_fall.lua)
local function fall(w, ids)
  for _, p in ipairs(ids) do w:set_velocity(p, V0[1], V0[2], V0[3]) end
  local x0 = {}
  for k, p in ipairs(ids) do x0[k] = { w:position(p) } end
  w:run{ seconds = T }
  local n, h, g = T * 60 * N, 1 / 60 / N, { 0, -9.81, 0 }
  local mean = { 0, 0, 0 }
  for k, p in ipairs(ids) do
    local x = { w:position(p) }
    for c = 1, 3 do mean[c] = mean[c] + (x[c] - x0[k][c]) / #ids end
  end
  local off, worst = 0, 0
  for c = 1, 3 do
    off = math.max(off, math.abs(mean[c] - (n * h * V0[c] + h * h * g[c] * n * (n + 1) / 2)))
  end
  for k, p in ipairs(ids) do
    local x, d = { w:position(p) }, 0
    for c = 1, 3 do d = d + (x[c] - x0[k][c] - mean[c]) ^ 2 end
    worst = math.max(worst, math.sqrt(d))
  end
  return worst, off
end

local n = T * 60 * N
local tol_v = 4 * n * eps * (10 / (1 / 60 / N) + 15)
local TOL = 2 * (2 * n * eps * 10 + (1 / 60 / N) * n * tol_v)

local bodies = {
  chain = function(w)
    local ids = {}
    for i = 1, 81 do
      ids[i] = w:particle{ pos = { (i - 1) * 0.05, 5 + 0.02 * math.sin(0.9 * i), 0.02 * math.cos(0.6 * i) } }
    end
    for i = 1, 80 do w:distance(ids[i], ids[i + 1]) end
    return ids
  end,
  cloth = function(w)
    return w:cloth{ origin = { 0, 5, 0 }, size = { 1, 1 }, res = { 20, 20 }, bend = 0.01 }.particles
  end,
  ["block of tets"] = function(w)
    return w:lattice{ min = { 0, 5, 0 }, max = { 0.3, 5.3, 0.3 }, res = { 4, 4, 4 }, tets = true, young = 1e5,
                      poisson = 0.3 }.particles
  end,
}

for _, name in ipairs{ "chain", "cloth", "block of tets" } do
  test("a free " .. name .. " falls undeformed, VBD and XPBD", function()
    for _, solver in ipairs{ "vbd", "gauss-seidel" } do
      local w = world(solver)
      local d, off = fall(w, bodies[name](w))
      print(string.format("# %s, %s: %.3g m off its shape, its mean %.3g m off free fall", name, solver, d, off))
      expect.le(d, TOL, solver .. ": off its shape (m)")
      expect.le(off, TOL, solver .. ": its mean off free fall (m)")
    end
  end)
end
