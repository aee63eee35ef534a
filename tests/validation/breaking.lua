-- breaking.lua: break_strain is a tensile limit. strain = (length - rest) / rest; a link
-- breaks when it exceeds +break_strain, never when compressed, however far. Checked
-- two ways: with immovable ends at set lengths (the strain is exact), and with a mass
-- hanging from and standing on a compliant link, whose static strain is -+ alpha m g / rest
-- (XPBD: the link is a spring of stiffness 1/alpha; Macklin et al. 2016).

local function fixed_pair(len, rest, break_strain)
  local w = wobble.world{ gravity = { 0, 0, 0 } }
  local p = w:particle{ pos = { 0, 0, 0 }, mass = 0 }
  local q = w:particle{ pos = { len, 0, 0 }, mass = 0 }
  local c = w:distance(p, q, { rest = rest, break_strain = break_strain })
  w:step()
  return c:broken(), c:strain()
end

test("immovable ends: a link breaks past +break_strain, not below it, never compressed", function()
  -- rest 1, limit 0.1: lengths 1.2 (strain +0.2), 1.05 (+0.05), 0.5 (-0.5), 0.01 (-0.99)
  local broken, strain = fixed_pair(1.2, 1, 0.1)
  expect.near(strain, 0.2, 1e-12)
  expect.truthy(broken, "stretched 20% with a 10% limit")
  expect.falsy((fixed_pair(1.05, 1, 0.1)), "stretched 5% with a 10% limit")
  expect.falsy((fixed_pair(0.5, 1, 0.1)), "compressed to half")
  expect.falsy((fixed_pair(0.01, 1, 0.1)), "compressed to 1%")
end)

-- a mass m on a link of compliance alpha to a pinned particle, above (+1) or below (-1)
-- it, placed at its static length rest - side * alpha m g (a load applied at once would
-- swing to twice that strain): the strain stays -side * alpha m g / rest
local function spring(side, break_strain)
  local g, m, alpha, rest = 9.81, 1, 0.01, 1
  local w = wobble.world{ gravity = { 0, -g, 0 }, substeps = 20, damping = 2 }
  local top = w:particle{ pos = { 0, 0, 0 }, mass = 0 }
  local p = w:particle{ pos = { 0, side * (rest - side * alpha * m * g), 0 }, mass = m }
  local c = w:distance(top, p, { rest = rest, compliance = alpha, break_strain = break_strain })
  w:run{ seconds = 3 }
  return c, -side * alpha * m * g / rest
end

test("a hanging mass breaks a link whose limit is below alpha m g / rest, and only then", function()
  local c, expected = spring(-1, 0.5)
  expect.falsy(c:broken())
  expect.rel(c:strain(), expected, 0.02, "static stretch alpha m g")
  expect.truthy((spring(-1, 0.5 * expected)):broken(), "limit half the static strain")
  expect.falsy((spring(-1, 1.5 * expected)):broken(), "limit 1.5 times the static strain")
end)

test("a mass standing on a link compresses it by alpha m g without breaking it", function()
  local c, expected = spring(1, 0.01)
  expect.rel(c:strain(), expected, 0.02, "static compression alpha m g")
  expect.lt(expected, -0.01 * 5, "compressed five times the limit")
  expect.falsy(c:broken(), "compression never breaks a link")
end)
