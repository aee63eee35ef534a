-- contact_forces.lua: w:contacts(), the particle-particle contacts of the last substep,
-- against statics.
--
-- A contact's force is its XPBD multiplier over h^2: lambda = depth / (w_a + w_b),
-- F = lambda / h^2 (src/core/contact.c). For a particle of mass m at rest on an immovable
-- one, each substep gravity moves it by g h^2 (its velocity was zeroed by the last
-- velocity pass), the contact takes that back: depth = g h^2, lambda = m g h^2, F = m g
-- exactly, up to round-off; 1e-6 relative leaves room for a settling transient only.
-- The same holds for a settled stack: once the positions repeat from substep to substep
-- with no velocity left, each particle's correction must give back exactly the g h^2 it
-- fell, so every contact carries the weight above it (checked every frame of the last
-- 20, 1e-6 relative again; the stack settles within the first few frames).

local g, m, r = 9.81, 0.3, 0.1

local function contact_between(w, a, b)
  for _, c in ipairs(w:contacts()) do
    if (c.a == a and c.b == b) or (c.a == b and c.b == a) then return c end
  end
end

test("a particle resting on an immovable one: one contact of force m g", function()
  local w = wobble.world{ gravity = {0, -g, 0} }
  local floor = w:particle{ pos = {0, 0, 0}, mass = 0, radius = r }
  local top = w:particle{ pos = {0, 2 * r, 0}, mass = m, radius = r }
  w:run{ frames = 30 }
  local cs = w:contacts()
  expect.eq(#cs, 1, "one contact")
  local c = contact_between(w, floor, top)
  assert(c, "no contact between the two particles")
  expect.near(c.force, m * g, 1e-6 * m * g, "force = m g")
  -- the normal points from a to b: from the lower id (floor) up to the top particle
  expect.eq(c.a, floor, "a")
  expect.near(c.normal[1], 0, 1e-9, "normal x")
  expect.near(c.normal[2], 1, 1e-9, "normal y")
  expect.near(c.normal[3], 0, 1e-9, "normal z")
  -- the depth is g h^2, far from the force: a readout of one for the other fails
  local h = w:dt() / w:substeps()
  expect.near(c.depth, g * h * h, 1e-6 * g * h * h, "depth = g h^2")
end)

test("two particles side by side without overlap: no contact", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  w:particle{ pos = {0, 0, 0}, mass = 1, radius = r }
  w:particle{ pos = {2 * r + 1e-3, 0, 0}, mass = 1, radius = r }
  w:run{ frames = 10 }
  expect.eq(#w:contacts(), 0, "no contact")
end)

test("a stack of three: the bottom contact carries 2 m g, the top one m g", function()
  local w = wobble.world{ gravity = {0, -g, 0} }
  local floor = w:particle{ pos = {0, 0, 0}, mass = 0, radius = r }
  local p1 = w:particle{ pos = {0, 2 * r, 0}, mass = m, radius = r }
  local p2 = w:particle{ pos = {0, 4 * r, 0}, mass = m, radius = r }
  w:run{ frames = 120 }
  for _ = 1, 20 do
    w:step()
    expect.eq(#w:contacts(), 2, "two contacts")
    expect.near(contact_between(w, floor, p1).force, 2 * m * g, 1e-6 * 2 * m * g, "bottom contact 2 m g")
    expect.near(contact_between(w, p1, p2).force, m * g, 1e-6 * m * g, "top contact m g")
  end
end)

test("stacks of 2 to 5 with the defaults (radius 0.02, 10 substeps): each contact carries the weight above it, at rest", function()
  -- loose particles of 1 kg made touching on an immovable one: the same statics as above,
  -- the bottom contact n m g; and no velocity left (each particle's corrections give back
  -- exactly the g h^2 it fell: the positions repeat). XPBD's, named: under VBD the contact
  -- sweeps still stop at a thousandth of the contact distance (src/core/contact.c, sweep),
  -- and stacks of 3 and 4 read 2.44 / 1.58 / 0.76 and 4.53 / 3.45 / 2.32 / 1.16 m g
  for n = 2, 5 do
    local w = wobble.world{ solver = "gauss-seidel" }
    local base = w:particle{ pos = {0, 0.5, 0}, mass = 0 }
    local q = {}
    for i = 1, n do q[i] = w:particle{ pos = {0, 0.5 + 0.04 * i, 0}, mass = 1 } end
    w:run{ seconds = 2 }
    for _ = 1, 10 do
      w:step()
      local below = base
      for i = 1, n do
        local c = contact_between(w, below, q[i])
        assert(c, "no contact under particle " .. i .. " of " .. n)
        expect.near(c.force, (n - i + 1) * g, 1e-6 * n * g, "stack of " .. n .. ": contact under particle " .. i)
        below = q[i]
      end
      local fastest = 0
      for i = 1, n do
        local vx, vy, vz = w:velocity(q[i])
        fastest = math.max(fastest, math.abs(vx), math.abs(vy), math.abs(vz))
      end
      expect.lt(fastest, 1e-9, "stack of " .. n .. ": at rest")
    end
  end
end)

test("contacts off: w:contacts() is empty", function()
  local w = wobble.world{ gravity = {0, -g, 0}, contacts = false }
  w:particle{ pos = {0, 0, 0}, mass = 0, radius = r }
  w:particle{ pos = {0, 1.5 * r, 0}, mass = m, radius = r }
  w:step()
  expect.eq(#w:contacts(), 0, "none")
end)
