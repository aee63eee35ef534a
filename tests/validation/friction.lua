-- friction.lua: Coulomb friction on a plane.
--
-- The contact model, per substep h (derived from the step, not measured from it):
--  * A particle resting on a plane sinks by the normal part of its prediction,
--    depth = g_n h^2, and is pushed back out: the normal impulse per substep is
--    m depth / h = m g_n h, exactly the weight's.
--  * Static friction: if the tangential slip of the substep, h |v_t|, is below
--    mu depth = mu g_n h^2 (i.e. |v_t| < mu g_n h), the slip is undone: the particle
--    stops. Otherwise dynamic friction removes mu depth / h = mu g_n h of tangential
--    speed: a deceleration of exactly mu g_n, Coulomb's law.
--
-- Sliding on a level plane from v0 (Coulomb: stops after v0^2/(2 mu g) in v0/(mu g)):
-- the substep k moves by h v_k with v_k = v0 - k a h (a = mu g) while v_k >= a h. With
-- N = floor(v0/(a h)) moving substeps and r = v0/(a h) - N in [0, 1), the distance is
--   D = h N v0 - a h^2 N(N-1)/2 = v0^2/(2 a) + h v0 / 2 - a h^2 r (r + 1) / 2,
-- so D - v0^2/(2 mu g) lies in [h v0/2 - mu g h^2, h v0/2]: that interval (plus 1e-9
-- of round-off) is the tolerance. The particle is captured in substep N + 1, at
-- t = (N + 1) h in (v0/(mu g), v0/(mu g) + h]: within one substep of Coulomb's time.

local g = 9.81

local function slide(mu, v0, substeps, r)
  r = r or 0.05
  local w = wobble.world{ gravity = { 0, -g, 0 }, dt = 1 / 60, substeps = substeps }
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, friction = mu }
  local p = w:particle{ pos = { 0, r, 0 }, vel = { v0, 0, 0 }, mass = 1, radius = r }
  local t_stop
  w:run{ seconds = v0 / (mu * g) + 0.5, on_frame = function(w, frame, t)
    local vx = w:velocity(p)
    if not t_stop and math.abs(vx) < 1e-9 then t_stop = t end
  end }
  local x, y = w:position(p)
  return x, y, t_stop, w:dt() / substeps
end

test("sliding stops after v0^2 / (2 mu g), within one substep of v0 / (mu g)", function()
  for _, case in ipairs{ { 0.4, 3, 10 }, { 0.2, 2, 10 }, { 0.8, 5, 4 }, { 0.4, 3, 40 } } do
    local mu, v0, s = case[1], case[2], case[3]
    local x, y, t_stop, h = slide(mu, v0, s)
    local D, T = v0 * v0 / (2 * mu * g), v0 / (mu * g)
    local what = string.format("mu %g, v0 %g, substeps %d", mu, v0, s)
    expect.ge(x - D, h * v0 / 2 - mu * g * h * h - 1e-9, what .. ": distance - v0^2/(2 mu g)")
    expect.le(x - D, h * v0 / 2 + 1e-9, what .. ": distance - v0^2/(2 mu g)")
    expect.near(y, 0.05, 1e-12, what .. ": stays on the plane")
    -- t_stop is the end of the frame in which it stopped: in [T, T + h + dt)
    expect.truthy(t_stop, what .. ": stopped")
    if t_stop then
      expect.ge(t_stop, T - 1e-9, what .. ": stop time")
      expect.lt(t_stop - 1 / 60, T + h + 1e-9, what .. ": stop time")
    end
  end
end)

test("sliding distance converges to v0^2 / (2 mu g) as h -> 0", function()
  -- the error is h v0 / 2 to leading order: 4x the substeps, 1/4 of the error
  local mu, v0 = 0.5, 4
  local D = v0 * v0 / (2 * mu * g)
  local x1, _, _, h1 = slide(mu, v0, 5)
  local x2, _, _, h2 = slide(mu, v0, 20)
  expect.lt(math.abs(x2 - D), math.abs(x1 - D), "smaller error with smaller h")
  expect.near(x2 - D, h2 * v0 / 2, mu * g * h2 * h2 + 1e-9)
end)

-- An incline at angle th: the plane's normal is (-sin th, cos th, 0), downhill is
-- (-cos th, -sin th, 0); g_n = g cos th, g_t = g sin th.
local function incline(th, mu, frames)
  local n = { -math.sin(th), math.cos(th), 0 }
  local w = wobble.world{ gravity = { 0, -g, 0 }, dt = 1 / 60, substeps = 10 }
  w:collider{ shape = "plane", normal = n, offset = 0, friction = mu }
  local r = 0.05
  local p = w:particle{ pos = { r * n[1], r * n[2], 0 }, mass = 1, radius = r }
  w:run{ frames = frames }
  local x, y = w:position(p)
  local vx, vy = w:velocity(p)
  local down = { -math.cos(th), -math.sin(th) }
  return (x - r * n[1]) * down[1] + (y - r * n[2]) * down[2], vx * down[1] + vy * down[2],
         x * n[1] + y * n[2]
end

test("incline steeper than atan(mu): slides with a = g (sin th - mu cos th)", function()
  -- each substep the tangential speed grows by g sin th h and loses mu g cos th h (the
  -- slip always exceeds the static threshold since tan th > mu): after n substeps
  -- v = n h a exactly, and s_n = h^2 (a n (n-1)/2 + n g sin th), which exceeds
  -- a t^2 / 2 by h t (g sin th - a / 2) >= 0 and at most h t g sin th.
  -- Round-off on v: as in free fall, 4 n eps (|x|/h + |v|) with |x| <= 3 m.
  local th, mu, frames = math.rad(30), 0.2, 60
  local s, v, dn = incline(th, mu, frames)
  local a = g * (math.sin(th) - mu * math.cos(th))
  local h, n = (1 / 60) / 10, frames * 10
  local t = n * h
  expect.near(v, a * t, 4 * n * 2 ^ -52 * (3 / h + a * t), "speed down the slope")
  expect.ge(s - a * t * t / 2, -1e-9, "distance")
  expect.le(s - a * t * t / 2, h * t * g * math.sin(th) + 1e-9, "distance")
  expect.near(dn, 0.05, 1e-12, "stays on the plane")
end)

test("incline shallower than atan(mu): static friction holds it exactly", function()
  -- the slip of each substep, g sin th h^2, is below mu g cos th h^2: undone every
  -- substep, so the particle does not move at all (round-off only)
  local s, v, dn = incline(math.rad(20), 0.5, 120)
  expect.near(s, 0, 1e-12, "no creep")
  expect.near(v, 0, 1e-9, "at rest")
  expect.near(dn, 0.05, 1e-12, "on the plane")
end)
