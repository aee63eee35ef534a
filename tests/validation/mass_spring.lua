-- mass_spring.lua: the period of a mass on a compliant constraint (gravity 0).
--
-- A mass m on a link of compliance alpha (k = 1/alpha, w = sqrt(k/m)) to an immovable
-- particle, displaced along the link and released. Per substep XPBD is implicit
-- Euler: with u the stretch, u_{n+1} = (u_n + h v_n) / (1 + w^2 h^2) and
-- v_{n+1} = (u_{n+1} - u_n)/h, i.e. v_{n+1} = v_n - h w^2 u_{n+1}. Its eigenvalues are
-- z = 1/(1 -+ i w h): a rotation by atan(w h) per substep with a decay
-- |z| = (1 + w^2 h^2)^(-1/2). The discrete period is therefore
--        T_h = 2 pi h / atan(w h),
-- which tends to 2 pi / w as w h -> 0 and is clearly longer when w h is large (7.8%
-- at w h = 0.5). A single constraint converges in one iteration, so iterations do not
-- matter.
--
-- Measurement: one frame per substep (substeps = 1, dt = h), zero crossings of u by
-- linear interpolation. For u = A e^(-s t) cos(W t + p) (s = ln(1 + w^2 h^2)/(2h),
-- W = atan(w h)/h) the interpolated root is off by at most
--   h^2/8 * max|u''| / min|u'|  <=  h^2/8 * (2 s + W^2 h) * e^(s h) / cos(W h)
-- per crossing; the mean period over P periods (2P half periods between the first
-- and the last crossing used) is off by at most twice that over P. The amplitude
-- decays by |z|^(T_h/h) per period: P is kept where it is still >> round-off.

local function crossings(wh, h, periods, iterations)
  local m, w0 = 1.0, wh / h
  local alpha = 1 / (m * w0 * w0)
  local w = wobble.world{ gravity = { 0, 0, 0 }, dt = h, substeps = 1, iterations = iterations or 1 }
  local anchor = w:particle{ pos = { 0, 0, 0 }, mass = 0 }
  local p = w:particle{ pos = { 1.1, 0, 0 }, mass = m } -- stretched by 0.1
  w:distance(anchor, p, { compliance = alpha, rest = 1 })
  local Th = 2 * math.pi * h / math.atan(wh)
  local c, pu, pt = {}, 0.1, 0
  w:run{ frames = math.ceil((periods + 1) * Th / h), on_frame = function(w, frame, t)
    local u = w:position(p) - 1
    if (pu > 0 and u <= 0) or (pu < 0 and u >= 0) then
      c[#c + 1] = pt + (t - pt) * pu / (pu - u)
    end
    pu, pt = u, t
  end }
  return c, Th, 2 * math.pi / w0
end

local function bound(wh, h, P)
  local s = math.log(1 + wh * wh) / (2 * h)
  local W = math.atan(wh) / h
  local per_crossing = h * h / 8 * (2 * s + W * W * h) * math.exp(s * h) / math.cos(W * h)
  return 2 * per_crossing / P
end

local function check(wh, h, P, iterations)
  local c, Th, Tc = crossings(wh, h, P, iterations)
  expect.ge(#c, 2 * P + 1, "enough zero crossings")
  if #c < 2 * P + 1 then return end
  local Tm = (c[2 * P + 1] - c[1]) / P
  local tol = bound(wh, h, P)
  expect.near(Tm, Th, tol, string.format("w h = %g: period vs 2 pi h / atan(w h)", wh))
  return Tm, Th, Tc, tol
end

test("w h = 0.5: period is 2 pi h / atan(w h), not 2 pi / w", function()
  -- the amplitude falls by 0.22 per period: 8 periods leave 0.1 * 0.22^8 = 5e-7 m
  local Tm, Th, Tc, tol = check(0.5, 0.01, 8)
  if not Tm then return end
  expect.gt(math.abs(Tm - Tc), 50 * tol, "differs from the continuous period 2 pi / w")
  expect.rel(Th, Tc * 1.0784, 1e-3) -- the formula itself: 7.8% longer at w h = 0.5
end)

test("w h = 0.5 with 4 iterations: the same period", function()
  check(0.5, 0.01, 8, 4)
end)

test("w h = 1: period 8 h (atan 1 = pi/4)", function()
  -- decay 0.5 per period: 6 periods leave 0.1 / 64
  local Tm, Th = check(1.0, 0.004, 6)
  if Tm then expect.near(Th, 8 * 0.004, 1e-15) end
end)

test("w h = 0.05: period close to 2 pi / w, still on the discrete formula", function()
  -- decay 0.855 per period: 10 periods leave 0.02 m
  local Tm, Th, Tc, tol = check(0.05, 0.002, 10)
  if Tm then expect.rel(Tm, Tc, 1e-3, "within 0.1% of the continuous period") end
end)
