-- box_contact.lua: what a box collider does to a particle, beyond its distance.
--
-- Normals: a particle just inside a box is pushed out through the nearest face,
-- along that face's outward normal, to its own radius outside the face; the other
-- two coordinates do not change. Made inside, it goes out at max_depenetration (0.25 m/s:
-- one step of 1/60 s without substeps takes 0.25/60 m of its 0.05 m) and keeps no
-- speed; without gravity or velocity the push is the only motion, so positions are
-- exact up to rounding (1e-12 m) once it is out, after 12 steps (17 for the last case).
--
-- Surface velocity (a conveyor): a box moving sideways at v carries a particle
-- resting on it with friction mu. Kinetic friction accelerates the particle at
-- mu g (Coulomb) until it moves with the belt, at t1 = v / (mu g); static friction
-- then keeps it there. So at time t > t1 its velocity is v and it has travelled
-- x = v t - v^2 / (2 mu g). The solver applies friction per substep from the
-- penetration gravity makes in that substep (g h^2, impulse mu g h), i.e. the same
-- Coulomb law sampled every h = 1/600 s: x is within v h (1.7 mm) of the formula.

local R = 0.02

test("a particle just inside a face leaves through that face", function()
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = 1 }
  w:collider{ shape = "box", center = {0, 0, 0}, half = {1, 0.5, 2} }
  -- start, where it must end up: each 0.03 inside one face, far from the others
  local cases = {
    { {0.97, 0.1, 0.2}, {1 + R, 0.1, 0.2} },     { {-0.97, -0.1, 0.3}, {-1 - R, -0.1, 0.3} },
    { {0.2, 0.47, -0.5}, {0.2, 0.5 + R, -0.5} }, { {-0.3, -0.47, 0.5}, {-0.3, -0.5 - R, 0.5} },
    { {0.1, 0.2, 1.97}, {0.1, 0.2, 2 + R} },     { {0.4, -0.2, -1.97}, {0.4, -0.2, -2 - R} },
    -- nearer to +y (0.05) than to +x (0.1) or +z (0.5)
    { {0.9, 0.45, 1.5}, {0.9, 0.5 + R, 1.5} },
  }
  local ids = {}
  for i, c in ipairs(cases) do ids[i] = w:particle{ pos = c[1], radius = R } end
  w:step()
  -- one step: max_depenetration x dt along the normal, no speed
  for i, c in ipairs(cases) do
    local x, y, z = w:position(ids[i])
    local d = math.sqrt((x - c[1][1]) ^ 2 + (y - c[1][2]) ^ 2 + (z - c[1][3]) ^ 2)
    expect.near(d, 0.25 / 60, 1e-12, "case " .. i .. " moved")
    local vx, vy, vz = w:velocity(ids[i])
    expect.lt(math.abs(vx) + math.abs(vy) + math.abs(vz), 1e-12, "case " .. i .. " speed")
  end
  w:run{ frames = 20 }
  for i, c in ipairs(cases) do
    local x, y, z = w:position(ids[i])
    local e = c[2]
    expect.near(x, e[1], 1e-12, "case " .. i .. " x")
    expect.near(y, e[2], 1e-12, "case " .. i .. " y")
    expect.near(z, e[3], 1e-12, "case " .. i .. " z")
  end
end)

test("a rotated box: the face normal turns with the box", function()
  -- 90 degrees about z: the box's local +x points along world +y, local -y along world +x
  local s = math.sqrt(0.5)
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = 1 }
  w:collider{ shape = "box", center = {0, 0, 0}, half = {1, 0.5, 2}, rotation = {s, 0, 0, s} }
  local a = w:particle{ pos = {0.1, 0.97, 0.3}, radius = R }   -- local (0.97, -0.1, 0.3): face +x
  local b = w:particle{ pos = {0.47, -0.2, -0.4}, radius = R } -- local (-0.2, -0.47, -0.4): face -y
  w:run{ frames = 20 } -- out at max_depenetration (above)
  local x, y, z = w:position(a)
  expect.near(x, 0.1, 1e-12); expect.near(y, 1 + R, 1e-12); expect.near(z, 0.3, 1e-12)
  x, y, z = w:position(b)
  expect.near(x, 0.5 + R, 1e-12); expect.near(y, -0.2, 1e-12); expect.near(z, -0.4, 1e-12)
end)

test("a conveyor: a box moving sideways carries a resting particle at its speed", function()
  local v, mu, g = 1.0, 1.0, 9.81
  local w = wobble.world{ gravity = {0, -g, 0}, substeps = 10 }
  local belt = w:collider{ shape = "box", center = {0, -0.5, 0}, half = {5, 0.5, 5}, friction = mu }
  belt:set_velocity(v, 0, 0)
  local p = w:particle{ pos = {0, R, 0}, radius = R }
  local t = 1.0
  w:run{ seconds = t }
  local x, y, z = w:position(p)
  local vx, vy, vz = w:velocity(p)
  expect.near(vx, v, 1e-9, "moves with the belt")
  expect.near(vy, 0, 1e-9, "rests on it")
  expect.near(vz, 0, 1e-12)
  expect.near(y, R, 1e-6, "on the top face")
  expect.near(x, v * t - v * v / (2 * mu * g), v / 600, "Coulomb until it catches up")
  expect.near(z, 0, 1e-12)
  -- the belt itself went where its velocity took it
  expect.near(belt:position(), v * t, 1e-9)
end)
