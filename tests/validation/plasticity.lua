-- plasticity.lua: plastic flow and breaking of distance constraints, once per frame.
--
-- Flow: when |strain| = |len - rest| / rest passes `yield`, the rest length moves
-- towards the current length by the part of the strain past yield, at a rate
-- min(1, creep dt) per frame:
--     rest' = rest + min(1, creep dt) (len - rest) (|e| - yield) / |e|
-- Breaking: a tensile strain past `break_strain` breaks the link (no flow then).
-- Links between two immovable particles keep their length exactly, so every frame
-- applies the formula to the same len and the values below are exact up to rounding.

local DT = 1 / 60

-- a link of length len between immovable particles, rest 1 unless given
local function link(len, opts)
  local w = wobble.world{ dt = DT }
  local a = w:particle{ pos = {0, 0, 0}, mass = 0 }
  local b = w:particle{ pos = {len, 0, 0}, mass = 0 }
  opts.rest = opts.rest or 1
  return w, w:distance(a, b, opts)
end

-- the rest lengths after each of n frames, by the formula
local function flow(rest, len, yield, creep, n)
  local out, rate = {}, math.min(1, creep * DT)
  for i = 1, n do
    local e = math.abs(len - rest) / rest
    if e > yield then rest = rest + rate * (len - rest) * (e - yield) / e end
    out[i] = rest
  end
  return out
end

test("stretched past yield: the rest length creeps towards the length", function()
  local w, c = link(1.5, { yield = 0.1, creep = 6 })   -- creep dt = 0.1
  w:step()
  -- e = 0.5: rest = 1 + 0.1 * 0.5 * 0.4 / 0.5 = 1.04
  expect.near(c:rest(), 1.04, 1e-12)
  local want = flow(1, 1.5, 0.1, 6, 30)
  expect.near(c:rest(), want[1], 1e-12)
  for i = 2, 30 do w:step() end
  expect.near(c:rest(), want[30], 1e-12)
  -- the flow stops where the strain is back at yield: len / (1 + yield)
  expect.gt(c:rest(), 1.3)
  expect.lt(c:rest(), 1.5 / 1.1)
end)

test("compressed past yield: the rest length shrinks", function()
  local w, c = link(0.6, { yield = 0.1, creep = 6 })
  w:step()
  -- e = 0.4: rest = 1 + 0.1 * (-0.4) * 0.3 / 0.4 = 0.97
  expect.near(c:rest(), 0.97, 1e-12)
end)

test("creep dt >= 1: the whole excess flows in one frame, then nothing", function()
  local w, c = link(1.5, { yield = 0.1, creep = 120 })  -- creep dt = 2, capped at 1
  w:step()
  expect.near(c:rest(), 1.4, 1e-12)                     -- 1 + 0.5 * 0.4 / 0.5
  w:step()
  expect.near(c:rest(), 1.4, 1e-12)                     -- strain 0.1 / 1.4 < yield
end)

test("within yield: no flow", function()
  local w, c = link(1.05, { yield = 0.1, creep = 6 })
  w:run{ frames = 10 }
  expect.eq(c:rest(), 1)
end)

test("breaking: past break_strain in tension, not in compression", function()
  local w, c = link(1.5, { break_strain = 0.3, yield = 0.1, creep = 6 })
  local w2, c2 = link(1.25, { break_strain = 0.3 })
  local w3, c3 = link(0.5, { break_strain = 0.3 })
  expect.falsy(c:broken())
  w:step(); w2:step(); w3:step()
  expect.truthy(c:broken(), "strain 0.5 > 0.3")
  expect.eq(c:rest(), 1, "a link that breaks does not flow")
  expect.eq(#w:breaks(), 1)
  expect.eq(w:stats().broken, 1)
  expect.falsy(c2:broken(), "strain 0.25 < 0.3")
  expect.falsy(c3:broken(), "strain -0.5 is compression")
end)

test("a broken link stops pulling", function()
  -- a soft link (k = 1 N/m) on a 1 kg particle moves it by ~1e-4 m in a frame, so
  -- the strain is still ~0.5 at the frame's end and the link breaks; from then on the
  -- particle flies on at the velocity it had
  local w = wobble.world{ gravity = {0, 0, 0} }
  local a = w:particle{ pos = {0, 0, 0}, mass = 0 }
  local b = w:particle{ pos = {1.5, 0, 0} }
  local c = w:distance(a, b, { rest = 1, compliance = 1, break_strain = 0.2 })
  w:step()
  expect.truthy(c:broken())
  local x1, vx = w:position(b), w:velocity(b)
  expect.lt(vx, 0, "pulled in during the frame it broke")
  w:run{ frames = 30 }
  expect.near(w:position(b), x1 + 30 * DT * vx, 1e-12, "free flight after the break")
  expect.eq(w:velocity(b), vx)
end)
