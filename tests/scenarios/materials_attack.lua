-- materials_attack.lua: hostile input to the materials API (bends, volumes, Neo-Hookean
-- tets, shape matching, pressure) that once got through; each case must be refused
-- cleanly or, where accepted, leave a finite state.

local function read(path)
  local f = assert(io.open(path, "rb")); local s = f:read("a"); f:close(); return s
end
local function write(path, s)
  local f = assert(io.open(path, "wb")); f:write(s); f:close()
end

local function tet_snapshot()
  local w = wobble.world{}
  local p = { w:particle{ pos = { 0, 0, 0 } }, w:particle{ pos = { 1, 0, 0 } },
              w:particle{ pos = { 0, 1, 0 } }, w:particle{ pos = { 0, 0, 1 } } }
  w:tet(p[1], p[2], p[3], p[4], { young = 1e3 })
  assert(w:save("materials_attack/tet.json"))
  return read("materials_attack/tet.json")
end

-- A snapshot's tet keeps Dm^-1 and V0 (= 1 / (6 |det Dm^-1|)); a hand-edited file whose
-- pair is singular or overflows made det F and w:energy() NaN after loading.
test("a tet's rest_inverse must be a finite, invertible match of its rest_volume", function()
  local s = tet_snapshot()
  local inv = s:match('"rest_inverse": (%b[])')
  assert(inv, "the snapshot writes rest_inverse")
  for name, bad in pairs{ zero = "[0, 0, 0, 0, 0, 0, 0, 0, 0]",
                          huge = "[1e308, 1e308, 1e308, 1e308, 1e308, 1e308, 1e308, 1e308, 1e308]",
                          scaled = "[2, 0, 0, 0, 2, 0, 0, 0, 2]" } do
    write("materials_attack/bad.json", (s:gsub('"rest_inverse": %b[]', '"rest_inverse": ' .. bad)))
    local w, err = wobble.load("materials_attack/bad.json")
    expect.eq(w, nil, name .. " is refused")
    expect.truthy(tostring(err):find("rest", 1, true), name .. ": " .. tostring(err))
  end
  -- the written pair itself still loads, with a finite energy
  local w = assert(wobble.load("materials_attack/tet.json"))
  local j, e = w:tet_info(1)
  expect.eq(j, 1)
  expect.truthy(e == e and w:energy() == w:energy(), "finite energy")
end)

-- tets = 0 (or "no") is true in Lua: from_mesh took it as tets = true and ran tetgen
test("from_mesh's tets must be a boolean", function()
  local m = wobble.mesh{ vertices = { {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1} },
                         triangles = { {1, 3, 2}, {1, 2, 4}, {1, 4, 3}, {2, 3, 4} } }
  local w = wobble.world{}
  local h = w:hash()
  expect.error(function() w:from_mesh(m, { tets = 0 }) end,
               "bad argument #2 to 'from_mesh' %(field 'tets': boolean expected, got number%)")
  expect.error(function() w:from_mesh(m, { tets = "no" }) end, "field 'tets': boolean expected, got string")
  expect.eq(w:hash(), h, "nothing added")
  expect.eq(w:particle_count(), 0)
end)

-- A Neo-Hookean tet body (young: w:tet elements, no volume constraints) could not be
-- written by w:save_tets ("no volume constraints"), and w:load_tets(.., {young}) gave it
-- tet_count = 0. The error of an empty world also said "in the body" for no body.
test("save_tets / load_tets carry Neo-Hookean tet bodies", function()
  local w = wobble.world{}
  local b = w:lattice{ min = {0, 0, 0}, max = {1, 1, 1}, res = {2, 2, 2}, tets = true, young = 1e5 }
  expect.eq(w:volume_count(), 0); expect.eq(b.tet_count, 6)
  expect.eq(w:save_tets("materials_attack/neo"), true)
  expect.eq(w:save_tets("materials_attack/neo_body", b), true)
  local v = wobble.world{}
  local c = assert(v:load_tets("materials_attack/neo", { young = 1e5 }))
  expect.eq(v:tet_count(), 6)
  expect.eq(c.tet_count, 6, "the body counts its Neo-Hookean tets")
  local u = wobble.world{}
  local d = assert(u:load_tets("materials_attack/neo_body"))
  expect.eq(d.tet_count, 6); expect.eq(u:volume_count(), 6)
  expect.error(function() wobble.world{}:save_tets("materials_attack/none") end, "no tets .* in the world")
end)

-- young = 1e300 was accepted and made a tet's energy -inf and w:energy() inf: refused
-- now past 1e14 Pa (100x diamond's modulus), from Lua and from a config alike, naming it.
test("young past 1e14 Pa is refused, the world unchanged", function()
  local w = wobble.world{}
  local p = { w:particle{ pos = { 0, 0, 0 } }, w:particle{ pos = { 1, 0, 0 } },
              w:particle{ pos = { 0, 1, 0 } }, w:particle{ pos = { 0, 0, 1 } } }
  local h = w:hash()
  expect.error(function() w:tet(p[1], p[2], p[3], p[4], { young = 1e300 }) end, "young")
  expect.error(function() w:lattice{ min = {0, 0, 0}, max = {1, 1, 1}, res = {2, 2, 2}, tets = true, young = 1e15 } end, "young")
  expect.eq(w:hash(), h)
  expect.eq(w:tet_count(), 0)
  w:tet(p[1], p[2], p[3], p[4], { young = 1e14 })
  local s, n = tet_snapshot():gsub('"young": [^,}]+', '"young": 1e300')
  expect.eq(n, 1, "the snapshot names young once")
  write("materials_attack/young.json", s)
  local w2, e2 = wobble.load("materials_attack/young.json")
  expect.eq(w2, nil)
  expect.truthy(tostring(e2):find("young", 1, true), "the error names young: " .. tostring(e2))
end)
