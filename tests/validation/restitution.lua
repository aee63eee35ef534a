-- restitution.lua: a particle dropped from h0 onto a plane of restitution e rises to
-- e^2 h0 (Newton's law of restitution: the rebound speed is e times the impact speed).
--
-- Discretisation (derived from the step): from rest, after k substeps v_k = k g h and
-- the drop is g h^2 k(k+1)/2 (symplectic Euler). The contact is found in the first
-- substep n whose prediction penetrates, g h^2 n(n+1)/2 > h0 >= g h^2 n(n-1)/2, and
-- the rebound velocity is u = e v_pre with v_pre = n g h the approach velocity of that
-- substep. Then V^2 = 2 g h0 lies within n g^2 h^2 of v_pre^2, so |v_pre - V| <= g h:
-- the O(g h) velocity error of detecting the contact at a substep. The particle
-- leaves from the surface (it is pushed out to it) and rises h(k u - g h k(k+1)/2) after
-- k substeps, whose maximum over k lies in [(u - g h/2)^2/(2g) - g h^2/8,
-- (u - g h/2)^2/(2g)]. Sampled once per frame, the apex is seen at most g dt^2/8 low.
-- Together the measured apex H lies in
--   [ (e (V - g h) - g h/2)^2 / (2 g) - g (h^2 + dt^2)/8 ,  (e (V + g h) - g h/2)^2 / (2 g) ],
-- an interval around e^2 h0 of width O(e V h): that is the tolerance.
-- Restitution is disabled below approach speeds of 2 g h (resting contact), far below V.

local g = 9.81

local function drop(e, h0, dt, substeps)
  local r = 0.05
  local w = wobble.world{ gravity = { 0, -g, 0 }, dt = dt, substeps = substeps }
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, restitution = e }
  local p = w:particle{ pos = { 0, r + h0, 0 }, mass = 1, radius = r }
  -- after the first contact (the first frame ending near the surface or moving up),
  -- the highest point until it starts falling again
  local hit, apex, lowest = false, -math.huge, math.huge
  local T = math.sqrt(2 * h0 / g) -- time to the ground
  w:run{ seconds = T + 2 * e * T + 0.2, on_frame = function(w)
    local _, y = w:position(p)
    local _, vy = w:velocity(p)
    lowest = math.min(lowest, y)
    if not hit and (vy >= 0 or y < r + 1e-9) then hit = true end
    if hit == true then
      apex = math.max(apex, y)
      if vy < 0 then hit = "done" end
    end
  end }
  return apex - r, lowest - r
end

local function band(e, h0, h, dt)
  local V = math.sqrt(2 * g * h0)
  local lo = (e * (V - g * h) - g * h / 2) ^ 2 / (2 * g) - g * (h * h + dt * dt) / 8
  local hi = (e * (V + g * h) - g * h / 2) ^ 2 / (2 * g)
  return lo, hi
end

test("first apex after a bounce is e^2 h0", function()
  for _, c in ipairs{ { 0.5, 1, 1 / 60, 10 }, { 0.8, 1, 1 / 240, 4 }, { 0.9, 2, 1 / 60, 20 }, { 1, 0.5, 1 / 120, 10 } } do
    local e, h0, dt, s = c[1], c[2], c[3], c[4]
    local H, low = drop(e, h0, dt, s)
    local lo, hi = band(e, h0, dt / s, dt)
    local what = string.format("e %g, h0 %g, h = 1/%d", e, h0, math.floor(s / dt + 0.5))
    expect.ge(H, lo - 1e-9, what .. string.format(": apex vs e^2 h0 = %g", e * e * h0))
    expect.le(H, hi + 1e-9, what .. string.format(": apex vs e^2 h0 = %g", e * e * h0))
    expect.ge(low, -1e-12, what .. ": never below the surface")
  end
end)

test("the band is narrow: O(g h) in velocity, about 2 e^2 V h in height", function()
  local lo, hi = band(0.5, 1, 1 / 600, 1 / 60)
  expect.lt(hi - lo, 0.02 * 0.25, "under 2% of e^2 h0")
  expect.truthy(lo <= 0.25 and 0.25 <= hi, "contains e^2 h0")
end)

test("restitution 0: no bounce", function()
  local H, low = drop(0, 1, 1 / 60, 10)
  expect.near(H, 0, 1e-12, "stays on the surface after the impact")
  expect.near(low, 0, 1e-12, "and not below it")
end)
