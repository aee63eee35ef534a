-- contacts_api.lua: the Lua side of particle-particle contacts: groups, the
-- builders' contact options, w:set_self_collide, wobble.world{contacts}, the default
-- radius, errors that change nothing, and snapshots that keep it all exactly.

test("groups: loose particles 0, a new group per body, w:group", function()
  local w = wobble.world{}
  local p = w:particle{ pos = {0, 0, 0} }
  local c = w:cloth{ res = {3, 3} }
  local r = w:rope{ segments = 3 }
  local l = w:lattice{ res = {2, 2, 2} }
  local q = w:particle{ pos = {0, 0, 0}, group = l.group }
  expect.eq(w:group(p), 0)
  expect.eq({ c.group, r.group, l.group }, { 1, 2, 3 })
  expect.eq(w:group(c.particles[9]), c.group)
  expect.eq(w:group(r.particles[1]), r.group)
  expect.eq(w:group(q), l.group, "w:particle{group} joins a body")
  local m = wobble.mesh{ vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                         triangles = {{1, 3, 2}, {1, 2, 4}, {1, 4, 3}, {2, 3, 4}} }
  local b = w:from_mesh(m)
  expect.eq(b.group, 4)
  expect.eq(w:group(b.particles[4]), 4)
  expect.eq(w:stats().particle_contacts, 0)
end)

test("default radius: half the particle spacing; a given radius is kept", function()
  local w = wobble.world{}
  local c = w:cloth{ size = {1, 2}, res = {11, 5} }                -- spacings 0.1 and 0.5
  expect.near(w:radius(c.particles[1]), 0.05, 1e-12)
  local r = w:rope{ from = {0, 0, 0}, to = {3, 0, 0}, segments = 10 }
  expect.near(w:radius(r.particles[5]), 0.15, 1e-12)
  local l = w:lattice{ min = {0, 0, 0}, max = {1, 2, 3}, res = {5, 3, 4} } -- 0.25, 1, 1
  expect.near(w:radius(l.particles[7]), 0.125, 1e-12)
  local k = w:lattice{ res = {2, 2, 2}, radius = 0.01 }
  expect.eq(w:radius(k.particles[1]), 0.01)
end)

test("bad contact options are refused, naming the key, changing nothing", function()
  local w = wobble.world{}
  local l = w:lattice{ res = {2, 2, 2} }
  local h = w:hash()
  expect.error(function() w:lattice{ res = {2, 2, 2}, friction = -1 } end, "friction")
  expect.error(function() w:cloth{ res = {2, 2}, collide = 1 } end, "collide")
  expect.error(function() w:rope{ self_collide = "yes" } end, "self_collide")
  expect.error(function() w:particle{ pos = {0, 0, 0}, group = -1 } end, "group")
  expect.error(function() w:particle{ pos = {0, 0, 0}, group = 0.5 } end, "group")
  expect.error(function() w:set_self_collide(0, true) end, "group must be a body's group")
  expect.error(function() w:set_self_collide(l.group) end, "boolean expected")
  expect.error(function() w:set_self_collide({}, true) end, "no integer 'group'")
  expect.error(function() w:set_self_collide(99, true) end, "no particle is in group 99")
  expect.error(function() w:set_self_collide({ group = 1.5 }, true) end, "no integer 'group'")
  expect.error(function() wobble.world{ contacts = 1 } end, "contacts")
  expect.error(function() w:load_particles("../../assets/logo.json", { colide = true }) end, "colide")
  expect.eq(w:hash(), h)
end)

test("w:set_self_collide turns a body's self-collision on and off", function()
  -- a rope of 12 links of 0.1 curled into a ring (links at rest) whose ends overlap
  -- (0.04 apart, contact distance 0.08); one substep, so the last substep's count is
  -- the overlap's
  local function curl(on, opt)
    local w = wobble.world{ gravity = {0, 0, 0}, substeps = 1 }
    local r = w:rope{ from = {0, 0, 0}, to = {1.2, 0, 0}, segments = 12, radius = 0.04, self_collide = opt }
    if on ~= nil then w:set_self_collide(r.group, on) end
    local step = 2 * math.pi / 12.4
    local R = 0.05 / math.sin(step / 2)
    for i, p in ipairs(r.particles) do w:set_position(p, R * math.cos(i * step), R * math.sin(i * step), 0) end
    w:step()
    return w:stats().particle_contacts
  end
  expect.eq(curl(nil), 0, "off by default")
  expect.gt(curl(true), 0, "w:set_self_collide(group, true)")
  expect.gt(curl(nil, true), 0, "self_collide = true")
  expect.eq(curl(false, true), 0, "w:set_self_collide(group, false)")
  -- the body itself stands for its group
  local w = wobble.world{ gravity = {0, 0, 0}, substeps = 1 }
  local r = w:rope{ from = {0, 0, 0}, to = {1.2, 0, 0}, segments = 12, radius = 0.04 }
  w:set_self_collide(r, true)
  local step = 2 * math.pi / 12.4
  local R = 0.05 / math.sin(step / 2)
  for i, p in ipairs(r.particles) do w:set_position(p, R * math.cos(i * step), R * math.sin(i * step), 0) end
  w:step()
  expect.gt(w:stats().particle_contacts, 0, "w:set_self_collide(body, true)")
end)

test("collide = false: a body passes through others", function()
  local function drop(collide)
    local w = wobble.world{}
    local lo = w:lattice{ min = {0, 0, 0}, max = {1, 1, 1}, res = {3, 3, 3} }
    lo:pin_all()
    local hi = w:lattice{ min = {0, 1.5, 0}, max = {1, 2.5, 1}, res = {3, 3, 3}, collide = collide }
    w:run{ seconds = 1 }
    local _, y = w:position(hi.particles[1])
    return y
  end
  expect.gt(drop(true), 1.0, "rests on the lower block")
  expect.lt(drop(false), 0, "falls through")
end)

test("load_particles: the config's parts are bodies of their own", function()
  local w = wobble.world{}
  local logo = assert(w:load_particles("../../assets/logo.json", { friction = 0.3 }))
  expect.truthy(logo.group and logo.group > 0)
  local seen = {}
  for _, part in ipairs(logo.parts) do
    expect.truthy(part.group and not seen[part.group], part.name .. ": a group of its own")
    seen[part.group] = true
    expect.eq(w:group(part.particles[1]), part.group)
  end
  expect.eq(#logo.parts, 6)
end)

test("load_particles of a snapshot: its bodies stay apart, in new groups", function()
  local w = wobble.world{}
  local a = w:lattice{ res = {2, 2, 2} }
  local b = w:lattice{ min = {2, 0, 0}, max = {3, 1, 1}, res = {2, 2, 2} }
  expect.eq(w:save("contacts_api/two.json"), true)
  local v = wobble.world{}
  v:particle{ pos = {9, 9, 9} }
  local c = v:cloth{ res = {2, 2} }
  local both = assert(v:load_particles("contacts_api/two.json"))
  local ga, gb = v:group(both.particles[1]), v:group(both.particles[9])
  expect.truthy(ga ~= gb and ga > c.group and gb > c.group, "two new groups")
  expect.eq(both.group, ga - a.group)
  expect.eq(gb - ga, b.group - a.group)
end)

test("snapshots keep groups, self-collision, friction and the contacts switch exactly", function()
  for _, contacts in ipairs{ true, false } do
    local w = wobble.world{ contacts = contacts }
    w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0 }
    local a = w:lattice{ min = {0, 0.1, 0}, max = {0.4, 0.5, 0.4}, res = {3, 3, 3}, friction = 0.4 }
    local b = w:cloth{ origin = {-0.2, 0.8, -0.2}, size = {0.8, 0.8}, res = {8, 8}, self_collide = true, friction = 0.1 }
    w:particle{ pos = {0.2, 1.2, 0.2}, radius = 0.05, friction = 0.2 }
    w:particle{ pos = {0.25, 1.4, 0.2}, radius = 0.05, group = a.group }
    w:run{ frames = 20 }
    local name = "contacts_api/snap.json"
    expect.eq(w:save(name), true)
    local v = assert(wobble.load(name))
    expect.eq(v:hash(), w:hash())
    expect.eq(v:group(b.particles[1]), b.group)
    for f = 1, 40 do
      w:step()
      v:step()
    end
    expect.eq(v:hash(), w:hash(), "stepped 40 frames more")
    expect.eq(v:stats().particle_contacts, w:stats().particle_contacts)
    if contacts then expect.gt(w:stats().particle_contacts, 0) end
  end
end)
