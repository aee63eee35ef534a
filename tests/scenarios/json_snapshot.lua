-- json_snapshot.lua: w:save(path) writes the full state and wobble.load(path) restores it
-- exactly: the same w:hash(), and both worlds stay bit-identical when stepped further.
-- The scene uses everything the state holds: settings, pinned and immovable particles,
-- plastic and broken constraints, a free constraint slot, every collider shape, a dead
-- collider slot, a collider mid-sweep with velocities, warnings.

local function read(name)
  local f = assert(io.open(name, "rb"))
  local s = f:read("a")
  f:close()
  return s
end

local function scene(solver)
  local w = wobble.world{ gravity = {0.3, -9.81, 0.1}, dt = 1 / 90, substeps = 7, iterations = 2,
                          damping = 0.05, solver = solver, relaxation = 1.2, threads = 2 }
  w:collider{ shape = "plane", normal = {0.1, 1, 0}, offset = -0.2, friction = 0.6, restitution = 0.3 }
  local gone = w:collider{ shape = "sphere", center = {9, 9, 9}, radius = 1 }
  w:collider{ shape = "sphere", center = {1.5, 0.2, 0}, radius = 0.3, friction = 0.2 }
  local press = w:collider{ shape = "box", center = {0, 2, 0}, half = {0.8, 0.1, 0.8},
                            rotation = {0.99, 0.05, 0.1, 0}, friction = 0.4 }
  local cap = w:collider{ shape = "capsule", a = {-2, 0.1, -1}, b = {-2, 0.1, 1}, radius = 0.15 }
  gone:remove()
  local block = w:lattice{ min = {-0.4, 0.1, -0.4}, max = {0.4, 0.7, 0.4}, res = {5, 4, 5}, mass = 2,
                           compliance = 1e-4, damping = 0.05, yield = 0.02, creep = 3, break_strain = 0.15 }
  local cloth = w:cloth{ origin = {-1, 1.5, -1}, size = {2, 2}, res = {9, 9}, compliance = 1e-6 }
  if solver == "vbd" then
    -- a flag of rigid links and bends swinging on its own, so that the file carries their
    -- multipliers (rigid bends on the big cloth, which the press and the block push, blow
    -- the scene up under VBD, whose contacts follow its sweeps)
    local flag = w:cloth{ origin = {3, 2, 3}, size = {0.6, 0.4}, res = {6, 4}, bend = 0 }
    w:pin(flag.particles[1])
  end
  cloth:pin_where(function(x, y, z) return z < -0.99 end)
  local rope = w:rope{ from = {1, 2, 0}, to = {2.5, 2, 0}, segments = 8, mass = 3 }
  w:pin(rope.first)
  local hub = w:particle{ pos = {-2, 1, 0}, mass = 0 }
  w:distance(hub, rope.first + 8, { compliance = 1e-3 })
  local doomed = w:distance(block.first, cloth.first)
  doomed:remove()
  cap:set_velocity(0.5, 0, 0)
  cap:set_angular_velocity(0, 1, 0)
  return w, press
end

-- the script's own motion of the press, frame by frame: both worlds get the same
local function drive(press, f)
  press:set_position(0.1 * math.sin(f / 10), 1.9 - 0.035 * f, 0)
  press:set_rotation(1, 0.01 * f, 0.1, 0)
end

for _, solver in ipairs{ "gauss-seidel", "jacobi", "vbd" } do
  test("save and load round-trip exactly (" .. solver .. ")", function()
    local w, press = scene(solver)
    for f = 1, 50 do
      drive(press, f)
      w:step()
    end
    drive(press, 51) -- a pose set, not yet reached: the sweep must survive the trip
    local stats = w:stats()
    expect.gt(stats.broken, 0, "some links broke")
    local name = "json_snapshot/" .. solver .. ".json"
    expect.eq(w:save(name), true)
    local v = assert(wobble.load(name))
    expect.eq(v:hash(), w:hash())
    expect.eq(v:frame(), w:frame())
    expect.eq(v:time(), w:time())
    expect.eq(v:particle_count(), w:particle_count())
    expect.eq(v:stats().distances, stats.distances)
    expect.eq(v:stats().broken, stats.broken)
    expect.eq(v:stats().colliders, stats.colliders)
    expect.eq({ v:gravity() }, { w:gravity() })
    expect.eq({ v:dt(), v:substeps(), v:iterations(), v:damping(), v:solver(), v:relaxation(), v:threads() },
              { w:dt(), w:substeps(), w:iterations(), w:damping(), w:solver(), w:relaxation(), w:threads() })
    -- the restored world saves to the very same bytes
    expect.eq(v:save(name .. ".again"), true)
    expect.truthy(read(name) == read(name .. ".again"), "a second save differs")
    -- stepped further, the two stay bit-identical (the press keeps moving in the original
    -- only through the pose it was given; the copy has no handle, so neither is driven)
    for f = 1, 60 do
      w:step()
      v:step()
      if w:hash() ~= v:hash() then
        expect.eq(v:hash(), w:hash(), "frame " .. f .. " after the load")
        break
      end
    end
    expect.eq(v:hash(), w:hash())
    expect.eq(v:stats().broken, w:stats().broken)
  end)
end

test("VBD: the multipliers are what the file needs to step on exactly", function()
  -- the same scene under VBD, its snapshot's "vbd" part taken out: the loaded world
  -- starts its rigid links and bends from no multiplier and steps on differently; an XPBD
  -- world's file has no such part (its multipliers start each substep from 0)
  local w, press = scene("vbd")
  for f = 1, 30 do
    drive(press, f)
    w:step()
  end
  assert(w:save("json_snapshot/vbd_full.json"))
  local text = read("json_snapshot/vbd_full.json")
  expect.truthy(text:find('"bend_multipliers"', 1, true), "the VBD part is written")
  local cut, n = text:gsub(',\n    "vbd": %b{}', '')
  expect.eq(n, 1)
  local f = assert(io.open("json_snapshot/vbd_cut.json", "wb"))
  f:write(cut)
  f:close()
  local v, u = assert(wobble.load("json_snapshot/vbd_full.json")), assert(wobble.load("json_snapshot/vbd_cut.json"))
  expect.eq(u:hash(), w:hash(), "the same state")
  w:step(); v:step(); u:step()
  expect.eq(v:hash(), w:hash(), "with the multipliers: the same future")
  expect.truthy(u:hash() ~= w:hash(), "without them: another")
  local x = scene("gauss-seidel")
  x:step()
  assert(x:save("json_snapshot/xpbd.json"))
  expect.falsy(read("json_snapshot/xpbd.json"):find('"vbd"', 1, true), "none in an XPBD world's file")
  -- a VBD part that does not fit the world is refused, named
  local bad = text:gsub('"bend_errors": %[', '"bend_errors": [0, ', 1)
  f = assert(io.open("json_snapshot/vbd_bad.json", "wb"))
  f:write(bad)
  f:close()
  local ok, err = wobble.load("json_snapshot/vbd_bad.json")
  expect.falsy(ok)
  expect.truthy(tostring(err):find("snapshot.vbd.bend_errors", 1, true), tostring(err))
end)

test("a snapshot is a particle config too (a superset of the format)", function()
  local w = scene("gauss-seidel")
  w:run{ frames = 10 }
  assert(w:save("json_snapshot/as_config.json"))
  local u = wobble.world{}
  local b = assert(u:load_particles("json_snapshot/as_config.json"))
  expect.eq(b.count, w:particle_count())
  expect.eq(u:stats().distances, w:stats().distances)
  expect.eq(u:stats().colliders, w:stats().colliders)
  for _, p in ipairs{ 1, 50, b.count } do
    expect.eq({ u:position(p) }, { w:position(p) })
    expect.eq({ u:velocity(p) }, { w:velocity(p) })
    expect.eq(u:mass(p), w:mass(p))
    expect.eq(u:pinned(p), w:pinned(p))
  end
  expect.eq(u:frame(), 0, "the world's clock is its own")
end)

test("the file: readable JSON, doubles that round-trip, warnings kept", function()
  local w = wobble.world{}
  local p = w:particle{ pos = {0.1, 1 / 3, -2 ^ -1074}, mass = 3 }
  local q = w:particle{ pos = {1, 1, 0}, vel = {1e300, -1e300, 0} }
  w:distance(p, q)
  print("expected on stderr: a warning that particle 1 became non-finite (this overflow is on purpose)")
  w:step() -- 1e300 m/s in a link: its length overflows, the frame is undone and counted
  expect.eq(w:warnings(), 1)
  assert(w:save("json_snapshot/tiny.json"))
  local text = read("json_snapshot/tiny.json")
  expect.truthy(text:find('"format": "wobble-particles"', 1, true))
  expect.truthy(text:find('"version": 1', 1, true))
  expect.truthy(text:find("0.33333333333333331", 1, true), "17 significant digits")
  local v = assert(wobble.load("json_snapshot/tiny.json"))
  expect.eq({ v:position(p) }, { w:position(p) })
  expect.eq(v:mass(p), 3)
  local n, msg = v:warnings()
  expect.eq(n, 1)
  expect.eq(msg, select(2, w:warnings()))
  expect.eq(v:hash(), w:hash())
end)

test("saving where it cannot", function()
  local w = wobble.world{}
  local f = assert(io.open("json_snapshot/dir/x", "w"))
  f:close()
  local ok, err = w:save("json_snapshot/dir")
  expect.eq(ok, nil)
  expect.truthy(err:find("^json_snapshot/dir: "), err)
  expect.error(function() w:save("/tmp/wobble-never-written.json") end, "is outside the output folder")
  w:close()
  expect.error(function() w:save("json_snapshot/closed.json") end, "closed world")
end)

test("a loaded world gives handles: w:colliders() and w:distances() in slot order", function()
  local w, press = scene("gauss-seidel")
  for f = 1, 20 do
    drive(press, f)
    w:step()
  end
  expect.eq(w:save("json_snapshot/handles.json"), true)
  local v = assert(wobble.load("json_snapshot/handles.json"))
  local wc, vc = w:colliders(), v:colliders()
  expect.eq(#wc, w:stats().colliders)
  expect.eq(#vc, v:stats().colliders)
  expect.eq(#vc, 4) -- plane, sphere, box, capsule: the removed sphere's slot is skipped
  expect.truthy(wc[3] == press, "the original's handles are the ones it made")
  for i = 1, #vc do
    expect.eq(vc[i]:shape(), wc[i]:shape())
    expect.eq({ vc[i]:position() }, { wc[i]:position() })
    expect.truthy(vc[i]:world() == v)
  end
  local wd, vd = w:distances(), v:distances()
  expect.eq(#wd, w:stats().distances)
  expect.eq(#vd, #wd)
  for i = 1, #vd, 37 do
    expect.eq({ vd[i]:particles() }, { wd[i]:particles() })
    expect.eq(vd[i]:rest(), wd[i]:rest())
  end
  -- the press of the loaded world, driven through its handle, moves as the original does
  local vpress = vc[3]
  expect.eq(vpress:shape(), "box")
  for f = 21, 40 do
    drive(press, f)
    drive(vpress, f)
    w:step()
    v:step()
  end
  local x, y = vpress:position()
  expect.near(x, 0.1 * math.sin(4), 1e-12)
  expect.near(y, 1.9 - 0.035 * 40, 1e-12, "the loaded press moved")
  expect.eq(v:hash(), w:hash())
  -- a handle from the list is live: removing through it removes the collider
  vc[2]:remove()
  expect.eq(#v:colliders(), 3)
  expect.eq(#wobble.world{}:colliders(), 0)
  expect.eq(#wobble.world{}:distances(), 0)
end)

test("a snapshot with 20000 removed constraints: the free list loads (linear checks)", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local rope = w:rope{ from = {0, 0, 0}, to = {250, 0, 0}, segments = 25000 }
  local links = w:distances()
  expect.eq(#links, 25000)
  for i = 1, 20000 do links[i]:remove() end
  expect.eq(w:stats().distances, 5000)
  expect.eq(w:save("json_snapshot/holes.json"), true)
  local v = assert(wobble.load("json_snapshot/holes.json"))
  expect.eq(v:hash(), w:hash())
  expect.eq(v:stats().distances, 5000)
  -- the free list came back in the same order: new constraints take the same slots
  local a, b = w:distance(rope.first, rope.first + 2), v:distance(rope.first, rope.first + 2)
  expect.eq(w:hash(), v:hash())
  expect.truthy(w:distances()[1] == a and v:distances()[1] == b, "a removed slot is reused first")
  -- the same file as a particle config (the free list checked, then ignored)
  local u = wobble.world{}
  local body = assert(u:load_particles("json_snapshot/holes.json"))
  expect.eq(body.constraint_count, 5000)
end)
