-- catenary.lua: a chain hanging between two points at equal height settles to the
-- catenary y(x) = a cosh(x/a) + c, with a fixed by the length: 2 a sinh(D/(2a)) = L.
--
-- Set-up: N equal rigid links of length l = L/N, N - 1 equal movable masses, both end
-- particles immovable at (-D/2, 0) and (D/2, 0); started in a V shape, settled with
-- world damping (a uniform drag; with or without it the shape does not depend on the
-- size of g, so it cannot bias the shape).
--
-- Discretisation error (derived): in equilibrium the vertical tension of link i is
-- m g (i - (N-1)/2), so its slope is tan th_i = s_i / a_d, with s_i the arc length of
-- the link's midpoint from the vertex and a_d = H / (rho g) the discrete chain's
-- parameter. That is exactly the continuous catenary's slope (dy/dx = s/a) sampled at
-- midpoints: the nodes are the composite midpoint rule applied to
--   x(s) = int f,  f(s) = (1 + s^2/a^2)^(-1/2),    y(s) = int q,  q(s) = (s/a) f(s),
-- from the vertex (the middle node, N even). Its error is at most
--   e_x = l^2/24 int_0^{L/2} |f''| ds,   e_y = l^2/24 int_0^{L/2} |q''| ds.
-- The end condition x(L/2) = D/2 then fixes a_d within da = e_x / |dX/da| of a, and
-- the node heights, compared with the catenary at the node's own x, are off by at most
--   tol_q = |d(Y - Y_end)/da| da + slope_max (|dX/da| da + e_x) + 2 e_y
-- (derivatives of the arc-length parametrisation X(s; a) = a asinh(s/a),
-- Y(s; a) = sqrt(a^2 + s^2), taken numerically from these formulas).
-- The solver leaves a small residual stretch eps (Gauss-Seidel on a long chain does not
-- fully converge within a substep); it lengthens the chain to at most L (1 + eps), whose
-- catenary differs from the one of length L by tol_s (computed the same way). The test
-- requires eps < 1e-3 (an essentially inextensible chain) and the chain at rest.

local g, D, L, N = 9.81, 1.0, 1.5, 60

-- hyperbolic functions (not in Lua 5.4's math library)
local exp, log, sqrt = math.exp, math.log, math.sqrt
local function sinh(x) return (exp(x) - exp(-x)) / 2 end
local function cosh(x) return (exp(x) + exp(-x)) / 2 end
local function asinh(x) return log(x + sqrt(x * x + 1)) end -- x >= 0 here

local function solve_a(len)
  local lo, hi = 1e-3, 1e3
  for _ = 1, 200 do
    local a = (lo + hi) / 2
    if 2 * a * sinh(D / (2 * a)) > len then lo = a else hi = a end
  end
  return (lo + hi) / 2
end

local function ycat(a, x) return a * cosh(x / a) - a * cosh(D / (2 * a)) end

-- integral of |F''| over [0, L/2] for F(s) = fn(s/a): sampled finely (F is smooth, the
-- samples are 200x denser than the links)
local function int_abs_d2(fn, a)
  local n, S, sum = 200 * N, L / 2, 0
  local ds = S / n
  for i = 0, n - 1 do
    local s = (i + 0.5) * ds
    local d2 = (fn((s + ds) / a) - 2 * fn(s / a) + fn((s - ds) / a)) / (ds * ds)
    sum = sum + math.abs(d2) * ds
  end
  return sum
end

local function bound(a, l)
  local f = function(u) return 1 / math.sqrt(1 + u * u) end
  local q = function(u) return u / math.sqrt(1 + u * u) end
  local ex = l * l / 24 * int_abs_d2(f, a) * 1.01
  local ey = l * l / 24 * int_abs_d2(q, a) * 1.01
  local X = function(s, b) return b * asinh(s / b) end
  local Y = function(s, b) return math.sqrt(b * b + s * s) end
  local eta = 1e-6 * a
  local dXda_end = (X(L / 2, a + eta) - X(L / 2, a - eta)) / (2 * eta)
  local da = ex / math.abs(dXda_end)
  local dY, dX = 0, 0
  for i = 0, 100 do
    local s = L / 2 * i / 100
    local yp = Y(s, a + eta) - Y(L / 2, a + eta)
    local ym = Y(s, a - eta) - Y(L / 2, a - eta)
    dY = math.max(dY, math.abs(yp - ym) / (2 * eta))
    dX = math.max(dX, math.abs(X(s, a + eta) - X(s, a - eta)) / (2 * eta))
  end
  local slope = sinh(D / (2 * a))
  return dY * da + slope * (dX * da + ex) + 2 * ey
end

-- largest height difference between the catenaries of lengths L1 and L2 (same ends)
local function catenary_gap(L1, L2)
  local a1, a2, gap = solve_a(L1), solve_a(L2), 0
  for i = 0, 200 do
    local x = -D / 2 + D * i / 200
    gap = math.max(gap, math.abs(ycat(a1, x) - ycat(a2, x)))
  end
  return gap
end

local function chain(substeps, iterations, seconds)
  local w = wobble.world{ gravity = { 0, -g, 0 }, dt = 1 / 60, substeps = substeps,
                          iterations = iterations, damping = 2 }
  local half, ids = N // 2, {}
  local d = math.sqrt((L / 2) ^ 2 - (D / 2) ^ 2)
  for i = 0, N do
    local x, y
    if i <= half then x, y = -D / 2 + (D / 2) * i / half, -d * i / half
    else x, y = (D / 2) * (i - half) / half, -d + d * (i - half) / half end
    local ends = i == 0 or i == N
    ids[#ids + 1] = w:particle{ pos = { x, y, 0 }, mass = ends and 0 or 1 / (N - 1) }
  end
  for i = 1, N do w:distance(ids[i], ids[i + 1], { compliance = 0, rest = L / N }) end
  w:run{ seconds = seconds }
  return w, ids
end

test("the midpoint-rule bound is small against catenary vs parabola", function()
  -- the test has power: a parabola of the same span and length is far outside it
  local a = solve_a(L)
  expect.near(2 * a * sinh(D / (2 * a)), L, 1e-12, "a solves the length equation")
  local function parab_len(c) -- length of y = c (x^2 - D^2/4) over [-D/2, D/2]
    local n, s = 2000, 0
    for i = 0, n - 1 do
      local x = -D / 2 + D * (i + 0.5) / n
      s = s + math.sqrt(1 + (2 * c * x) ^ 2) * D / n
    end
    return s
  end
  local lo, hi = 0, 100
  for _ = 1, 100 do
    local c = (lo + hi) / 2
    if parab_len(c) < L then lo = c else hi = c end
  end
  local c, gap = (lo + hi) / 2, 0
  for i = 0, 100 do
    local x = -D / 2 + D * i / 100
    gap = math.max(gap, math.abs(c * (x * x - D * D / 4) - ycat(a, x)))
  end
  expect.gt(gap, 20 * bound(a, L / N), "parabola vs catenary gap over the bound")
end)

test("hanging chain settles on y = a cosh(x/a) + c", function()
  local w, ids = chain(40, 40, 12)
  local a = solve_a(L)
  local eps = w:max_strain()
  expect.lt(eps, 1e-3, "residual stretch of the rigid links")
  local ke = w:energy()
  expect.lt(ke, 1e-9, "at rest")
  -- what is left of the settling motion: every particle's speed is <= sqrt(2 ke / m)
  -- (m = 1/(N-1) each), its displacement amplitude <= speed / omega with
  -- omega >= sqrt(g / sag) for the slowest swinging mode (sag < 0.6 m)
  local settle = math.sqrt(2 * ke * (N - 1)) / math.sqrt(g / 0.6)
  local tol = bound(a, L / N) + catenary_gap(L, L * (1 + eps)) + settle + 1e-9
  local worst, sym = 0, 0
  for i, id in ipairs(ids) do
    local x, y = w:position(id)
    worst = math.max(worst, math.abs(y - ycat(a, x)))
    local xm, ym = w:position(ids[#ids + 1 - i])
    sym = math.max(sym, math.abs(x + xm), math.abs(y - ym))
  end
  expect.le(worst, tol, string.format("largest |y - y_catenary| (a = %.6f)", a))
  -- symmetric about x = 0 (the solver sweeps in one direction, so only to the bound)
  expect.le(sym, 2 * tol, "symmetry")
end)
