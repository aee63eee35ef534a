-- bend_break.lua: break_torque on bends against a static load.
--
-- A hinge along z (p1 = (0,1,0), p2 = (0,1,1), both pinned) between a pinned wing p3 and a
-- free wing p4 of mass m at horizontal distance d from the hinge, held level by a rigid
-- bend alone: the links p1-p4 and p2-p4 keep its distance from the hinge but are
-- horizontal, so they carry none of its weight. The bend then carries the moment of the
-- weight about the hinge, M = m g d, from the first substep on (everything starts at rest
-- in place), and XPBD's multiplier of an angle reads it: lambda / h^2 = M in N m
-- (b:force()). So a break_torque 2% above m g d holds for good and 2% below breaks in the
-- first frame, reported once in w:bend_breaks(); then the wing swings down on its links.

local M, D, G = 2, 0.5, 9.81

local function hinge(break_torque, frames)
  local w = wobble.world{ gravity = {0, -G, 0} }
  local p1 = w:particle{ pos = {0, 1, 0}, mass = 0 }
  local p2 = w:particle{ pos = {0, 1, 1}, mass = 0 }
  local p3 = w:particle{ pos = {-D, 1, 0.5}, mass = 0 }
  local p4 = w:particle{ pos = {D, 1, 0.5}, mass = M }
  w:distance(p1, p4)
  w:distance(p2, p4)
  local b = w:bend(p1, p2, p3, p4, { break_torque = break_torque })
  local reported = 0
  w:run{ frames = frames or 120, on_frame = function(w)
    for _, x in ipairs(w:bend_breaks()) do
      reported = reported + 1
      expect.truthy(x == b, "the handle reported is the bend's")
    end
  end }
  return w, b, p4, reported
end

test("break_torque: a bend breaks at the torque it carries (m g d)", function()
  local mgd = M * G * D
  local w, b, p4, reported = hinge(1.02 * mgd)
  expect.falsy(b:broken(), "2% above m g d holds")
  expect.eq(reported, 0)
  expect.near(b:force(), mgd, 1e-3 * mgd, "force() = m g d (N m)")
  local _, y = w:position(p4)
  expect.near(y, 1, 1e-3, "the wing stays level")

  local w2, b2, q4, reported2 = hinge(0.98 * mgd)
  expect.truthy(b2:broken(), "2% below m g d breaks")
  expect.eq(reported2, 1, "reported once, after the step that broke it")
  expect.eq(b2:force(), 0, "a broken bend carries nothing")
  local _, y2 = w2:position(q4)
  expect.lt(y2, 1 - D / 2, "and the wing swings down")
  expect.eq(w2:warnings(), 0, "no warning")
end)

test("break_torque: a broken bend stays broken through a snapshot", function()
  local w, b = hinge(0.5 * M * G * D)
  expect.truthy(b:broken())
  local path = "bend_break_snapshot.json"
  w:save(path)
  local v = wobble.load(path)
  expect.eq(v:hash(), w:hash(), "the same state")
  expect.truthy(v:bends()[1]:broken(), "broken after loading")
  w:step()
  v:step()
  expect.eq(v:hash(), w:hash(), "and the same future")
  -- saved unbroken with its break_torque (0 frames run): the loaded one breaks as well
  local u = hinge(0.98 * M * G * D, 0)
  expect.falsy(u:bends()[1]:broken())
  u:save(path)
  local lu = wobble.load(path)
  expect.eq(lu:hash(), u:hash(), "an unbroken one round-trips too")
  lu:step()
  expect.truthy(lu:bends()[1]:broken(), "break_torque came through the file")
end)

test("break_torque: refused when negative, named", function()
  local w = wobble.world{}
  local p = {}
  for i = 1, 4 do p[i] = w:particle{ pos = {i % 2, i // 2, i * 0.1} } end
  local ok, err = pcall(w.bend, w, p[1], p[2], p[3], p[4], { break_torque = -1 })
  expect.falsy(ok)
  expect.truthy(err:find("break_torque", 1, true), err)
end)
