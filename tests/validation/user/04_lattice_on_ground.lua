-- A builder body made resting on the ground the way a user writes it: a lattice block
-- from y = 0 on the ground plane y = 0. Its particles have the default contact radius
-- (half the spacing, docs/lua-api.md "Builders"), so its bottom layer starts r inside
-- the ground. Physically nothing should happen beyond the block settling onto its
-- bottom layer: it must not be launched, and comes to rest on the ground.
local S, RES = 0.5, 5               -- a 0.5 m cube, 5 x 5 x 5 particles: spacing 0.125, r = 0.0625
local r = S / (RES - 1) / 2
local g = 9.81

local function com(w, b)
  local sx, sy, sz = 0, 0, 0
  for _, p in ipairs(b.particles) do local x, y, z = w:position(p); sx, sy, sz = sx + x, sy + y, sz + z end
  local n = #b.particles
  return sx / n, sy / n, sz / n
end
local function com_vel(w, b)
  local sx, sy, sz = 0, 0, 0
  for _, p in ipairs(b.particles) do local x, y, z = w:velocity(p); sx, sy, sz = sx + x, sy + y, sz + z end
  local n = #b.particles
  return sx / n, sy / n, sz / n
end

test("a lattice made on the ground (from y = 0) is not launched and settles on it", function()
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, friction = 0.5 }
  local b = w:lattice{ min = { -S / 2, 0, -S / 2 }, max = { S / 2, S, S / 2 }, res = { RES, RES, RES }, mass = 1 }
  print(string.format("default radius %.4f (expected half the spacing, %.4f)", w:radius(b.particles[1]), r))
  local _, y0 = com(w, b)
  local top_com, max_up, max_speed = y0, 0, 0
  w:run{ seconds = 3, on_frame = function(w)
    local _, y = com(w, b)
    top_com = math.max(top_com, y)
    local vx, vy, vz = com_vel(w, b)
    max_up = math.max(max_up, vy)
    for _, p in ipairs(b.particles) do
      local ux, uy, uz = w:velocity(p)
      max_speed = math.max(max_speed, math.sqrt(ux * ux + uy * uy + uz * uz))
    end
  end }
  local _, y_end = com(w, b)
  local _, miny = w:bounds()
  local ke = w:energy()
  print(string.format("COM y: start %.4f, highest %.4f, end %.4f; max upward COM speed %.3f m/s; max particle speed "
    .. "%.3f m/s; lowest particle %.4f; kinetic at end %.2e J; warnings %d", y0, top_com, y_end, max_up, max_speed,
    miny, ke, (w:warnings())))
  -- pushed out of the ground by at most its radius: the COM may rise by r (plus 5 mm);
  -- anything more is the block being thrown
  expect.le(top_com, y0 + r + 0.005, "COM rises at most by the contact radius")
  -- README: an overlap is pushed out at no more than max_depenetration (0.25 m/s); the
  -- bottom layer is driven up at that speed from rest, and an elastic body whose base is
  -- driven at v overshoots it by at most v (undamped: its COM speed oscillates in [0, 2v])
  expect.lt(max_up, 2 * 0.25, "COM never moves up faster than twice the depenetration speed")
  expect.lt(max_speed, 1.0, "no particle flung")
  -- resting: bottom layer r above the ground (within 1 cm of sag), at rest
  expect.near(miny, r, 0.01, "bottom layer rests r above the ground")
  expect.lt(ke, 1e-3, "settled (kinetic energy under 1 mJ)")
end)

test("the same lattice made r above the ground (the README's placement) rests where made", function()
  local w = wobble.world{}
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, friction = 0.5 }
  local b = w:lattice{ min = { -S / 2, r, -S / 2 }, max = { S / 2, S + r, S / 2 }, res = { RES, RES, RES }, mass = 1 }
  local _, y0 = com(w, b)
  local top_com, max_speed = y0, 0
  w:run{ seconds = 3, on_frame = function(w)
    local _, y = com(w, b)
    top_com = math.max(top_com, y)
    for _, p in ipairs(b.particles) do
      local ux, uy, uz = w:velocity(p)
      max_speed = math.max(max_speed, math.sqrt(ux * ux + uy * uy + uz * uz))
    end
  end }
  local _, miny = w:bounds()
  local ke = w:energy()
  print(string.format("COM y: start %.4f, highest %.4f; max particle speed %.3f m/s; lowest %.4f; kinetic %.2e J",
    y0, top_com, max_speed, miny, ke))
  expect.le(top_com, y0 + 0.005, "does not rise")
  expect.lt(max_speed, 0.5, "no particle flung")
  expect.near(miny, r, 0.01, "bottom layer rests r above the ground")
  expect.lt(ke, 1e-3, "settled")
end)
