-- api_world.lua: the world binding: construction, settings, particles, stepping,
-- queries and the determinism hash (DESIGN §3).

test("world defaults", function()
  local w = wobble.world{ threads = 1 }
  expect.near(w:dt(), 1 / 60, 1e-15)
  expect.eq(w:substeps(), 10)
  expect.eq(w:iterations(), 1)
  expect.eq(w:solver(), "gauss-seidel")
  expect.eq(w:threads(), 1)
  expect.near(w:damping(), 0, 0)
  expect.near(w:relaxation(), 1, 0)
  local gx, gy, gz = w:gravity()
  expect.near(gx, 0, 0); expect.near(gy, -9.81, 1e-12); expect.near(gz, 0, 0)
  expect.eq(w:particle_count(), 0)
  expect.eq(w:frame(), 0)
  expect.near(w:time(), 0, 0)
  expect.truthy(wobble.world() ~= nil, "wobble.world() without a table")
end)

test("world with every key", function()
  local w = wobble.world{ gravity = {0, 0, -1}, dt = 0.01, substeps = 4, iterations = 3,
                          damping = 0.5, solver = "jacobi", relaxation = 1.5, threads = 2 }
  expect.near(w:dt(), 0.01, 0)
  expect.eq(w:substeps(), 4)
  expect.eq(w:iterations(), 3)
  expect.eq(w:solver(), "jacobi")
  expect.near(w:relaxation(), 1.5, 0)
  expect.eq(w:threads(), 2)
  local _, _, gz = w:gravity()
  expect.near(gz, -1, 0)
  local s = w:stats()
  expect.eq(s.substeps, 4); expect.eq(s.iterations, 3)
  expect.eq(s.solver, "jacobi"); expect.eq(s.threads, 2)
end)

test("setters round trip and refuse bad values unchanged", function()
  local w = wobble.world{}
  w:set_gravity(1, 2, 3)
  local x, y, z = w:gravity()
  expect.eq(x, 1); expect.eq(y, 2); expect.eq(z, 3)
  w:set_dt(0.02); expect.near(w:dt(), 0.02, 0)
  w:set_substeps(7); expect.eq(w:substeps(), 7)
  w:set_iterations(2); expect.eq(w:iterations(), 2)
  w:set_damping(0.1); expect.near(w:damping(), 0.1, 0)
  w:set_solver("jacobi"); expect.eq(w:solver(), "jacobi")
  w:set_relaxation(1.2); expect.near(w:relaxation(), 1.2, 0)
  w:set_threads(3); expect.eq(w:threads(), 3)
  expect.error(function() w:set_substeps(0) end, "substeps")
  expect.error(function() w:set_dt(-1) end, "dt must be")
  expect.error(function() w:set_solver("sor") end, "unknown solver 'sor'")
  expect.error(function() w:set_gravity(0, 0 / 0, 0) end, "finite number expected, got nan")
  expect.eq(w:substeps(), 7)
  expect.near(w:dt(), 0.02, 0)
  expect.eq(w:solver(), "jacobi")
end)

test("particle ids are 1-based and round trip", function()
  local w = wobble.world{}
  local a = w:particle{ pos = {1, 2, 3} }
  local b = w:particle{ pos = {4, 5, 6}, vel = {-1, 0, 1}, mass = 2, radius = 0.5 }
  expect.eq(a, 1); expect.eq(b, 2)
  expect.eq(math.type(a), "integer")
  expect.eq(w:particle_count(), 2)
  local x, y, z = w:position(b)
  expect.eq(x, 4); expect.eq(y, 5); expect.eq(z, 6)
  local vx, vy, vz = w:velocity(b)
  expect.eq(vx, -1); expect.eq(vy, 0); expect.eq(vz, 1)
  expect.eq(w:mass(a), 1); expect.eq(w:mass(b), 2)
  expect.eq(w:radius(b), 0.5)
  w:set_position(a, 7, 8, 9)
  x, y, z = w:position(a)
  expect.eq(x, 7); expect.eq(y, 8); expect.eq(z, 9)
  w:set_velocity(a, 0.5, 0.25, 0.125)
  vx, vy, vz = w:velocity(a)
  expect.eq(vx, 0.5); expect.eq(vy, 0.25); expect.eq(vz, 0.125)
  expect.eq(w:position(2.0), 4) -- an integral float is an id too
end)

test("mass 0 and pins hold particles in place", function()
  local w = wobble.world{}
  local fixed = w:particle{ pos = {0, 1, 0}, mass = 0 }
  local free = w:particle{ pos = {1, 1, 0} }
  local pinned = w:particle{ pos = {2, 1, 0} }
  w:pin(pinned)
  expect.truthy(w:pinned(pinned))
  expect.falsy(w:pinned(free))
  for _ = 1, 10 do w:step() end
  local _, y0 = w:position(fixed)
  local _, y1 = w:position(free)
  local _, y2 = w:position(pinned)
  expect.eq(y0, 1); expect.eq(y2, 1)
  expect.truthy(y1 < 1, "free particle falls")
  w:pin(free, {5, 6, 7})
  local x, y, z = w:position(free)
  expect.eq(x, 5); expect.eq(y, 6); expect.eq(z, 7)
  w:unpin(pinned)
  expect.falsy(w:pinned(pinned))
  w:step()
  local _, y3 = w:position(pinned)
  expect.truthy(y3 < 1, "unpinned particle falls")
end)

test("step advances time and frame", function()
  local w = wobble.world{ dt = 0.01 }
  w:particle{ pos = {0, 0, 0} }
  w:step(); w:step()
  expect.eq(w:frame(), 2)
  expect.eq(math.type(w:frame()), "integer")
  expect.near(w:time(), 0.02, 1e-12)
  -- free fall from rest: v = g t exactly with symplectic steps
  local _, vy = w:velocity(1)
  expect.near(vy, -9.81 * 0.02, 1e-9)
end)

test("queries return the documented shapes", function()
  local w = wobble.world{}
  expect.eq(w:bounds(), nil)
  expect.eq(select("#", w:bounds()), 1)
  w:particle{ pos = {-1, 2, 3}, vel = {1, 0, 0}, mass = 2 }
  w:particle{ pos = {4, -5, 6} }
  local b = { w:bounds() }
  expect.eq(#b, 6)
  expect.eq(b[1], -1); expect.eq(b[2], -5); expect.eq(b[3], 3)
  expect.eq(b[4], 4); expect.eq(b[5], 2); expect.eq(b[6], 6)
  local k, p = w:energy()
  expect.near(k, 1, 1e-12) -- 1/2 * 2 * 1^2
  expect.eq(type(p), "number")
  local px, py, pz = w:momentum()
  expect.near(px, 2, 1e-12); expect.near(py, 0, 0); expect.near(pz, 0, 0)
  expect.eq(select("#", w:angular_momentum()), 3)
  expect.eq(type(w:max_strain()), "number")
  local s = w:stats()
  expect.eq(s.particles, 2)
  expect.eq(s.distances, 0)
  for _, key in ipairs{ "broken", "colliders", "colours", "contacts", "projections",
                        "step_ms", "solve_ms", "warnings", "substeps", "iterations",
                        "solver", "threads" } do
    expect.truthy(s[key] ~= nil, "stats." .. key)
  end
  local n, msg = w:warnings()
  expect.eq(n, 0); expect.eq(msg, nil)
end)

test("hash: 16 hex digits, changes when stepping, equal for identical worlds", function()
  local function make()
    local w = wobble.world{}
    w:cloth{ origin = {0, 1, 0}, size = {1, 1}, res = {4, 4} }
    w:collider{ shape = "sphere", center = {0.5, 0, 0.5}, radius = 0.5 }
    return w
  end
  local a, b = make(), make()
  local h0 = a:hash()
  expect.eq(type(h0), "string")
  expect.eq(#h0, 16)
  expect.truthy(h0:match("^[0-9a-f]+$"), "lowercase hex")
  expect.eq(h0, b:hash())
  a:step()
  expect.truthy(a:hash() ~= h0, "hash changes after a step")
  b:step()
  expect.eq(a:hash(), b:hash())
  b:set_position(1, 0, 1, 1e-9)
  expect.truthy(a:hash() ~= b:hash(), "hash sees a tiny change")
end)

test("same results whatever the thread count", function()
  local function run(threads)
    local w = wobble.world{ threads = threads }
    w:cloth{ origin = {0, 1, 0}, size = {1, 1}, res = {8, 8} }
    w:run{ frames = 5 }
    return w:hash()
  end
  expect.eq(run(1), run(4))
end)

test("tostring of a world", function()
  local w = wobble.world{}
  w:particle{ pos = {0, 0, 0} }
  expect.truthy(tostring(w):match("^wobble%.world: 0x%x+ %(1 particles%)$") or
                tostring(w):match("^wobble%.world: .+ %(1 particles%)$"), tostring(w))
  w:close()
  expect.truthy(tostring(w):match("%(closed%)$"), tostring(w))
end)

test("numerical trouble is counted as a warning", function()
  local w = wobble.world{}
  -- a particle at the edge of the double range, pushed past it
  local p = w:particle{ pos = {1.797e308, 0, 0} }
  w:set_velocity(p, 1e308, 0, 0)
  print("expected on stderr: a warning that particle 1 became non-finite (this overflow is on purpose)")
  w:step(); w:step()
  local n, msg = w:warnings()
  expect.truthy(n >= 1, "warnings counted")
  expect.eq(type(msg), "string")
  local x = w:position(p)
  expect.truthy(x == x and x < math.huge, "state stays finite")
end)

test("module table", function()
  expect.eq(type(wobble.version), "string")
  expect.eq(require("wobble"), wobble)
  expect.eq(wobble.limits.particles, 1 << 24)
end)
