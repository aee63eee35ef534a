-- measures.lua: w:energy(), w:momentum(), w:angular_momentum() and w:hash() on
-- states whose values follow by hand. No stepping: the measures read the state as
-- set, so the expected values are exact (integers, or rounding at 1e-12).

test("potential energy: gravity -m g.x plus C^2 / (2 alpha) per compliant link", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local a = w:particle{ pos = {0, 0, 0} }
  local b = w:particle{ pos = {1.5, 0, 0} }
  w:distance(a, b, { rest = 1, compliance = 0.01 })        -- C = 0.5: 0.25 / 0.02 = 12.5 J
  local ke, pe = w:energy()
  expect.eq(ke, 0)
  expect.near(pe, 12.5, 1e-12)
  -- a rigid link stores nothing (alpha = 0 is not a spring), nor does one at rest
  local c = w:particle{ pos = {0, 2, 0} }
  w:distance(a, c, { rest = 1 })
  w:distance(b, c, { compliance = 1e-3 })
  _, pe = w:energy()
  expect.near(pe, 12.5, 1e-12)
end)

test("energy with gravity and velocities", function()
  local g = 9.81
  local w = wobble.world{ gravity = {0, -g, 0} }
  local a = w:particle{ pos = {0, 3, 0}, mass = 2, vel = {1, 2, 2} }     -- |v|^2 = 9
  local b = w:particle{ pos = {0, 3, 2}, mass = 0.5, vel = {0, 0, -4} }  -- |v|^2 = 16
  w:particle{ pos = {0, 10, 0}, mass = 0 }                                -- immovable: no energy
  w:distance(a, b, { rest = 1.5, compliance = 0.002 })                    -- C = 0.5
  local ke, pe = w:energy()
  expect.near(ke, 0.5 * 2 * 9 + 0.5 * 0.5 * 16, 1e-12)
  expect.near(pe, 2 * g * 3 + 0.5 * g * 3 + 0.25 / (2 * 0.002), 1e-9)
end)

test("momentum and angular momentum about the origin: sum of m v and m x cross v", function()
  local w = wobble.world{}
  w:particle{ pos = {1, 2, 3}, vel = {4, 5, 6}, mass = 2 }    -- m x*v = 2 (-3, 6, -3)
  w:particle{ pos = {0, 0, 1}, vel = {1, 0, 0}, mass = 0.5 }  -- 0.5 (0, 1, 0)
  w:particle{ pos = {5, 5, 5}, mass = 0 }                     -- immovable: at rest
  expect.eq({ w:momentum() }, { 8.5, 10, 12 })
  expect.eq({ w:angular_momentum() }, { -6, 12.5, -6 })
  -- a single particle circling the y axis counter-clockwise seen from +y: L along +y
  local u = wobble.world{}
  u:particle{ pos = {1, 0, 0}, vel = {0, 0, -1}, mass = 3 }
  expect.eq({ u:angular_momentum() }, { 0, 3, 0 })
end)

test("the hash sees every part of the state: a velocity alone changes it", function()
  local function make(vz)
    local w = wobble.world{}
    w:particle{ pos = {0, 1, 0} }
    w:particle{ pos = {1, 1, 0}, vel = {0, 0, vz} }
    return w
  end
  local w1, w2 = make(0), make(0)
  expect.eq(w1:hash(), w2:hash(), "equal states, equal hashes")
  local w3 = make(1e-9)
  expect.truthy(w3:hash() ~= w1:hash(), "a velocity differs: " .. w3:hash() .. " vs " .. w1:hash())
  w3:set_velocity(2, 0, 0, 0)
  expect.eq(w3:hash(), w1:hash(), "set back: equal again")
  w2:set_position(1, 0, 1 + 1e-12, 0)
  expect.truthy(w2:hash() ~= w1:hash(), "a position differs")
end)
