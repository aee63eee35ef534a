-- api_handles.lua: constraint and collider handles (id + generation), stale handle
-- detection, and the world's life cycle (__gc / __close safe twice).

local function pair(dist)
  local w = wobble.world{ gravity = {0, 0, 0} }
  local p = w:particle{ pos = {0, 0, 0} }
  local q = w:particle{ pos = {dist or 1, 0, 0} }
  return w, p, q
end

test("distance constraint handle", function()
  local w, p, q = pair(2)
  local c = w:distance(p, q)
  expect.eq(type(c), "userdata")
  expect.near(c:rest(), 2, 1e-12)   -- rest defaults to the current length
  expect.near(c:length(), 2, 1e-12)
  expect.near(c:strain(), 0, 1e-12)
  expect.eq(c:broken(), false)
  expect.eq(type(c:force()), "number")
  local a, b = c:particles()
  expect.eq(a, p); expect.eq(b, q)
  expect.eq(math.type(a), "integer")
  expect.eq(c:world(), w)
  expect.truthy(c:valid())
  local c2 = w:distance(p, q, { compliance = 1e-3, rest = 1.5, damping = 0.1,
                                yield = 0.1, creep = 1, break_strain = 2 })
  expect.near(c2:rest(), 1.5, 1e-12)
  expect.eq(w:stats().distances, 2)
  expect.truthy(tostring(c):match("^wobble%.distance: .+ %(1%-2%)$"), tostring(c))
end)

test("a rigid constraint holds its length", function()
  local w = wobble.world{}
  local top = w:particle{ pos = {0, 1, 0}, mass = 0 }
  local bob = w:particle{ pos = {1, 1, 0} }
  local c = w:distance(top, bob)
  w:run{ frames = 30 }
  expect.near(c:length(), 1, 1e-3)
  expect.truthy(c:force() > 0, "a hanging pendulum pulls")
end)

test("__eq compares the constraint, not the userdata", function()
  local w, p, q = pair()
  local c = w:distance(p, q)
  local d = w:distance(p, q)
  expect.truthy(c == c)
  expect.truthy(c ~= d, "two constraints differ")
  local broke = w:breaks()
  expect.eq(#broke, 0)
  local w2, p2, q2 = pair()
  local e = w2:distance(p2, q2)
  expect.truthy(c ~= e, "same slot in another world differs")
end)

test("removed constraints leave stale handles", function()
  local w, p, q = pair()
  local c = w:distance(p, q)
  local d = w:distance(p, q)
  c:remove()
  expect.falsy(c:valid())
  expect.error(function() c:rest() end, "stale constraint handle")
  expect.error(function() c:force() end, "removed or world closed")
  expect.error(function() c:remove() end, "stale constraint handle")
  expect.truthy(tostring(c):match("%(stale%)$"), tostring(c))
  expect.eq(w:stats().distances, 1)
  expect.near(d:rest(), 1, 1e-12)
  -- a new constraint may reuse the slot: the old handle stays stale
  local e = w:distance(p, q)
  expect.error(function() c:length() end, "stale constraint handle")
  expect.truthy(e ~= c)
  expect.near(e:rest(), 1, 1e-12)
end)

test("breaking constraints are reported by w:breaks()", function()
  local w, p, q = pair()
  local c = w:distance(p, q, { break_strain = 0.5 })
  w:pin(p)
  w:pin(q, {10, 0, 0}) -- held at strain 9: it must break
  w:step()
  expect.truthy(c:broken(), "stretched past break_strain")
  local broke = w:breaks()
  expect.eq(#broke, 1)
  expect.truthy(broke[1] == c)
  expect.eq(w:stats().broken, 1)
  w:step()
  expect.eq(#w:breaks(), 0)
end)

test("closing the world makes handles stale", function()
  local w, p, q = pair()
  local c = w:distance(p, q)
  local col = w:collider{ shape = "plane" }
  w:close()
  expect.error(function() c:rest() end, "stale constraint handle %(removed or world closed%)")
  expect.error(function() col:position() end, "stale collider handle %(removed or world closed%)")
  expect.falsy(c:valid()); expect.falsy(col:valid())
  expect.truthy(tostring(c):match("stale"))
end)

test("handles keep their world alive", function()
  local c, col = (function()
    local w, p, q = pair(3)
    return w:distance(p, q), w:collider{ shape = "sphere", radius = 2 }
  end)()
  collectgarbage(); collectgarbage()
  expect.near(c:rest(), 3, 1e-12)
  expect.eq(col:shape(), "sphere")
  expect.eq(c:world():particle_count(), 2)
end)

test("__gc and __close are safe twice, close is idempotent", function()
  local w = wobble.world{}
  w:particle{ pos = {0, 0, 0} }
  local mt = getmetatable(w)
  if type(mt) == "table" then
    mt.__close(w); mt.__close(w)
    mt.__gc(w); mt.__gc(w)
  end
  w:close(); w:close()
  expect.truthy(w:closed())
  expect.error(function() w:particle_count() end, "closed world")
  do
    local v <close> = wobble.world{}
    v:particle{ pos = {0, 0, 0} }
    v:close() -- and closed again at the end of the block
  end
  local kept
  do
    local v <close> = wobble.world{}
    kept = v
  end
  expect.truthy(kept:closed())
  for _ = 1, 20 do wobble.world{}:particle{ pos = {0, 0, 0} } end
  collectgarbage(); collectgarbage()
end)

test("collider handle", function()
  local w = wobble.world{}
  local s = w:collider{ shape = "sphere", center = {1, 2, 3}, radius = 0.5, friction = 0.3, restitution = 0.2 }
  expect.eq(s:shape(), "sphere")
  local x, y, z = s:position()
  expect.eq(x, 1); expect.eq(y, 2); expect.eq(z, 3)
  expect.near(s:distance(1, 4, 3), 1.5, 1e-12)
  expect.near(s:distance(1, 2, 3), -0.5, 1e-12)
  local f, r = s:material()
  expect.near(f, 0.3, 1e-12); expect.near(r, 0.2, 1e-12)
  s:set_position(0, 0, 0)
  x, y, z = s:position()
  expect.eq(x, 0); expect.eq(y, 0); expect.eq(z, 0)
  s:set_velocity(1, 0, 0)
  local vx = s:velocity()
  expect.eq(vx, 1)
  s:set_angular_velocity(0, 1, 0)
  local box = w:collider{ shape = "box", center = {0, -1, 0}, half = {1, 0.5, 1}, rotation = {2, 0, 0, 0} }
  local qw, qx, qy, qz = box:rotation()
  expect.near(qw, 1, 1e-12); expect.eq(qx, 0); expect.eq(qy, 0); expect.eq(qz, 0)
  box:set_rotation(0, 0, 1, 0)
  qw, qx, qy, qz = box:rotation()
  expect.near(math.abs(qy), 1, 1e-12)
  local plane = w:collider{ shape = "plane", normal = {0, 2, 0}, offset = -1 }
  expect.eq(plane:shape(), "plane")
  expect.near(plane:distance(0, 0, 0), 0.5, 1e-12) -- the points with n.x = offset: y = -0.5
  local cap = w:collider{ shape = "capsule", a = {0, 0, 0}, b = {1, 0, 0}, radius = 0.25 }
  expect.near(cap:distance(0.5, 1, 0), 0.75, 1e-12)
  expect.eq(w:stats().colliders, 4)
  expect.truthy(tostring(cap):match("^wobble%.collider: .+ %(capsule%)$"), tostring(cap))
  expect.truthy(cap == cap); expect.truthy(cap ~= plane)
  cap:remove()
  expect.error(function() cap:shape() end, "stale collider handle")
  expect.error(function() cap:set_position(0, 0, 0) end, "stale collider handle")
  expect.eq(w:stats().colliders, 3)
  expect.eq(s:world(), w)
end)

test("a ground plane stops a falling particle", function()
  local w = wobble.world{}
  local p = w:particle{ pos = {0, 1, 0}, radius = 0.1 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
  w:run{ seconds = 2 }
  local _, y = w:position(p)
  expect.near(y, 0.1, 1e-3)
end)

test("a moved collider pushes particles", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local p = w:particle{ pos = {0, 0, 0}, radius = 0 }
  local s = w:collider{ shape = "sphere", center = {-2, 0, 0}, radius = 1 }
  s:set_position(0.5, 0, 0)
  w:step()
  -- the sphere sweeps substep by substep: the particle rides ahead of it, no tunnelling
  local x = w:position(p)
  expect.near(x, 1.5, 1e-6)
end)
