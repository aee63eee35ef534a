-- pendulum.lua: period of a large-amplitude rigid pendulum against the exact
-- T = 4 sqrt(L/g) K(sin(theta0/2)), K the complete elliptic integral of the first kind.
--
-- Set-up: an immovable pivot, a bob of mass m on a rigid (compliance 0) distance
-- constraint of length L, released from rest at theta0 = 90 degrees. The period is
-- measured from zero crossings of x (the bob passing under the pivot): T = t3 - t1.
--
-- Error budget of the measurement (derived; nothing taken from the code's output):
--  1. Energy drift of PBD's projection. Per substep the prediction
--     x~ = 2x_n - x_{n-1} + h^2 g leaves the circle by d = h^2 (w^2 L + g cos th) (the
--     tension per unit mass, times h^2); the correction is radial at the *new* point,
--     which is rotated by w h from the old one (a symmetric, energy-conserving SHAKE
--     step would push along the old radius). The tangential difference d w h slows the
--     bob by h^2 w (w^2 L + g cos th) per substep: an energy loss rate of at most
--        dE/dt <= m L h wmax^2 (wmax^2 L + g),   wmax^2 = 2 g (1 - cos th0) / L.
--     (For uniform rotation this is the exact Delta^3 decay of the step angle.) So the
--     amplitude stays in [th_min, th0] with cos th_min = cos th0 + dE/(m g L) over the
--     measured time, and as T(th) grows with th the measured period lies in
--     [T(th_min), T(th0)].
--  2. Phase error of the underlying second-order (Verlet-like) step: O((wmax h)^2) T.
--  3. Linear interpolation of the crossings between frames (dt apart): at x = 0,
--     x'' = 0 and |x''/x'| <= dt (g/L + wmax^2) within a frame, so each crossing is off
--     by at most dt^3 (g/L + wmax^2) / 8; two crossings per period.

local g, L, m = 9.81, 1.0, 1.0

-- K(k) = pi / (2 AGM(1, sqrt(1 - k^2)))
local function K(k)
  local a, b = 1, math.sqrt(1 - k * k)
  for _ = 1, 60 do
    local an, bn = (a + b) / 2, math.sqrt(a * b)
    a, b = an, bn
    if math.abs(a - b) < 1e-16 then break end
  end
  return math.pi / (2 * a)
end

local function period(th0) return 4 * math.sqrt(L / g) * K(math.sin(th0 / 2)) end

-- the swinging bob: crossing times of x = 0 (linear interpolation between frames)
local function swing(th0, dt, substeps, frames, iterations)
  local w = wobble.world{ gravity = { 0, -g, 0 }, dt = dt, substeps = substeps, iterations = iterations or 1 }
  local pivot = w:particle{ pos = { 0, 0, 0 }, mass = 0 }
  local bob = w:particle{ pos = { L * math.sin(th0), -L * math.cos(th0), 0 }, mass = m }
  w:distance(pivot, bob, { compliance = 0 })
  local crossings, px, pt = {}, L * math.sin(th0), 0
  w:run{ frames = frames, on_frame = function(w, frame, t)
    local x = w:position(bob)
    if (px > 0 and x <= 0) or (px < 0 and x >= 0) then
      crossings[#crossings + 1] = pt + (t - pt) * px / (px - x)
    end
    px, pt = x, t
  end }
  return crossings
end

test("elliptic integral K by the AGM (known values)", function()
  -- K(0) = pi/2; K(1/sqrt2) = Gamma(1/4)^2 / (4 sqrt(pi)) = 1.8540746773013719
  expect.near(K(0), math.pi / 2, 1e-15)
  expect.near(K(1 / math.sqrt(2)), 1.8540746773013719, 1e-14)
end)

local function check_period(th0, dt, substeps)
  local h = dt / substeps
  local T0 = period(th0)
  local c = swing(th0, dt, substeps, math.ceil(1.4 * T0 / dt))
  expect.ge(#c, 3, "three zero crossings in 1.4 periods")
  if #c < 3 then return end
  local Tm = c[3] - c[1]
  -- 1. amplitude range over the run (to c[3])
  local w2 = 2 * g * (1 - math.cos(th0)) / L
  local dE = c[3] * m * L * h * w2 * (w2 * L + g)
  local thmin = math.acos(math.min(1, math.cos(th0) + dE / (m * g * L)))
  -- 2. + 3.
  local extra = w2 * h * h * T0 + 2 * dt ^ 3 * (g / L + w2) / 8
  local lo, hi = period(thmin) - extra, T0 + extra
  expect.ge(Tm, lo, string.format("period %.6f s vs [T(th_min), T(th0)] = [%.6f, %.6f]", Tm, lo, hi))
  expect.le(Tm, hi, string.format("period %.6f s vs [T(th_min), T(th0)] = [%.6f, %.6f]", Tm, lo, hi))
  -- half periods agree with each other to the same budget
  expect.near(c[2] - c[1], c[3] - c[2], hi - lo, "successive half periods")
  return Tm, lo, hi
end

test("pendulum at 90 degrees: period = 4 sqrt(L/g) K(sin 45deg) (200 substeps)", function()
  local th0 = math.pi / 2
  local Tm, lo, hi = check_period(th0, 1 / 60, 200)
  -- the budget is tight enough to tell the exact period from the small-angle one
  -- (2 pi sqrt(L/g) is 15% shorter)
  local small = 2 * math.pi * math.sqrt(L / g)
  expect.lt(small, lo, "the small-angle period lies outside the band")
  expect.lt((hi - lo) / period(th0), 0.01, "band narrower than 1%")
end)

test("pendulum at 150 degrees (400 substeps)", function()
  local th0 = 150 * math.pi / 180
  check_period(th0, 1 / 60, 400)
end)
