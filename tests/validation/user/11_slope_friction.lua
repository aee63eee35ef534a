-- Coulomb friction on a slope: a body resting on a plane tilted by theta with friction
-- mu stays put when tan(theta) < mu and slides with a = g (sin theta - mu cos theta) when
-- tan(theta) > mu. A single w:particle and a w:lattice block, defaults otherwise.
local g, MU = 9.81, 0.5

local function slope(tan_t)
  local th = math.atan(tan_t)
  -- the plane's normal tilted about z: downhill is +x along the surface
  local n = { math.sin(th), math.cos(th), 0 }
  local d = { math.cos(th), -math.sin(th), 0 }  -- downhill direction
  return th, n, d
end

local function along(w, ids, d)
  local s = 0
  for _, p in ipairs(ids) do local x, y, z = w:position(p); s = s + x * d[1] + y * d[2] + z * d[3] end
  return s / #ids
end

local function particle_case(tan_t)
  local th, n, d = slope(tan_t)
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = n, offset = 0, friction = MU }
  local rad = 0.02
  local p = w:particle{ pos = { n[1] * rad, n[2] * rad, 0 } }   -- resting on the plane: r above it
  local s0 = along(w, { p }, d)
  w:run{ seconds = 1 }
  return along(w, { p }, d) - s0, th
end

local function block_case(tan_t)
  local th, n, d = slope(tan_t)
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = n, offset = 0, friction = MU }
  local S, r = 0.3, 0.05
  local b = w:lattice{ min = { -S / 2, r, -S / 2 }, max = { S / 2, r + S, S / 2 }, res = { 4, 4, 4 }, mass = 1 }
  -- made on a level ground r above it, then turned onto the slope about the origin
  local c, s = math.cos(th), math.sin(th)
  for _, p in ipairs(b.particles) do
    local x, y, z = w:position(p)
    w:set_position(p, c * x + s * y, -s * x + c * y, z)
  end
  local s0 = along(w, b.particles, d)
  w:run{ seconds = 1 }
  return along(w, b.particles, d) - s0, th
end

for _, case in ipairs{ { "particle", particle_case }, { "lattice block", block_case } } do
  local name, f = case[1], case[2]
  test(name .. " on a slope with tan(theta) = 0.4 < mu = 0.5 stays put", function()
    local moved = f(0.4)
    print(string.format("%s, tan 0.4: moved %.2e m downhill in 1 s", name, moved))
    -- static friction holds it exactly at position level: 1 mm allowed
    expect.lt(math.abs(moved), 1e-3, "no sliding below tan theta = mu")
  end)
  test(name .. " on a slope with tan(theta) = 0.7 > mu = 0.5 slides with g (sin - mu cos)", function()
    local moved, th = f(0.7)
    local a = g * (math.sin(th) - MU * math.cos(th))
    print(string.format("%s, tan 0.7: slid %.4f m in 1 s, expected %.4f m", name, moved, a / 2))
    -- dynamic friction at velocity level per substep: first-order in h, and the start
    -- (static friction breaking away) costs a substep or two: 5%
    expect.rel(moved, a / 2, 0.05, "sliding distance a t^2 / 2")
  end)
end
