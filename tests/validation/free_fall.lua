-- free_fall.lua: a particle in free fall against the exact solution of the integrator.
--
-- The step integrates with symplectic Euler per substep h = dt/substeps:
--   v_k = v_{k-1} + g h,   x_k = x_{k-1} + h v_k.
-- From v_0 and x_0, after n substeps (t = n h):
--   v_n = v_0 + n h g                            (exact: the velocity of free fall, g t)
--   x_n = x_0 + n h v_0 + h^2 g n (n + 1) / 2    (= x_0 + v_0 t + g t^2/2 + g h t / 2)
-- so the velocity must equal v_0 + g t to round-off, at every frame and for any substeps.
--
-- Round-off: the step recomputes v = (x - x_prev) / h each substep, which loses up to
-- ~2 eps |x| / h (a subtraction and a division of numbers of size |x|), plus eps |v| for
-- the update itself: after n substeps |dv| <= 4 n eps (|x|max / h + |v|max). Positions
-- accumulate h times that per substep plus 2 eps |x| per update.

local eps = 2.0 ^ -52

local function fall(substeps, g, x0, v0, frames)
  local w = wobble.world{ gravity = g, dt = 1 / 60, substeps = substeps }
  local p = w:particle{ pos = x0, vel = v0, mass = 1.5, radius = 0.05 }
  local h = w:dt() / w:substeps()
  local worst_v, worst_x = 0, 0 -- largest error / tolerance ratios seen
  w:run{ frames = frames, on_frame = function(w, frame)
    local n = frame * substeps
    local x = { w:position(p) }
    local v = { w:velocity(p) }
    for i = 1, 3 do
      local ve = v0[i] + n * h * g[i]
      local xe = x0[i] + n * h * v0[i] + h * h * g[i] * n * (n + 1) / 2
      local xmax = math.abs(x0[i]) + math.abs(xe - x0[i]) + 1
      local vmax = math.abs(v0[i]) + math.abs(ve) + 1
      local tol_v = 4 * n * eps * (xmax / h + vmax)
      local tol_x = 2 * n * eps * xmax + h * n * tol_v
      worst_v = math.max(worst_v, math.abs(v[i] - ve) / tol_v)
      worst_x = math.max(worst_x, math.abs(x[i] - xe) / tol_x)
    end
  end }
  return worst_v, worst_x, w, p
end

test("free fall: v = g t exactly at every frame (10 substeps)", function()
  local wv, wx = fall(10, { 0, -9.81, 0 }, { 0, 5, 0 }, { 0, 0, 0 }, 120)
  expect.le(wv, 1, "velocity error / round-off bound")
  expect.le(wx, 1, "position error / round-off bound")
end)

test("free fall: any substeps, tilted gravity, initial velocity", function()
  for _, s in ipairs{ 1, 3, 10, 37 } do
    local wv, wx = fall(s, { 1.5, -9.81, 0.25 }, { 0.5, 3, -1 }, { 2, 4, -1 }, 60)
    expect.le(wv, 1, "substeps " .. s .. ": velocity error / bound")
    expect.le(wx, 1, "substeps " .. s .. ": position error / bound")
  end
end)

test("free fall: the trajectory approaches x0 + v0 t + g t^2 / 2 as h -> 0", function()
  -- x_n - (x0 + v0 t + g t^2/2) = g h t / 2 exactly (see the header): halving h halves it.
  -- Tolerance: the round-off bound above at t = 1 s, |x| <= 5.9 m, n <= 1200, is
  -- 2 n eps |x| + h n 4 n eps |x| / h < 1e-8 m, far below the g h t / 2 >= 4e-3 m tested.
  local t = 1
  for _, s in ipairs{ 5, 10, 20 } do
    local _, _, w, p = fall(s, { 0, -9.81, 0 }, { 0, 0, 0 }, { 0, 0, 0 }, 60)
    local _, y = w:position(p)
    local h = (1 / 60) / s
    expect.near(y - (-9.81 * t * t / 2), -9.81 * h * t / 2, 1e-8, "substeps " .. s)
  end
end)
