-- neo_io.lua: Neo-Hookean tets (core/tet.c) in and out of files.
--
-- w:save / wobble.load keep every tet (corners, E, nu, and the rest state Dm^-1 and V0
-- written with 17 digits, so bit for bit): the same w:hash() and the same future. The
-- copy whose "tets" section is cut out drifts from the original (the round trip test can
-- fail). A config's tets take their rest state from the particles when it is not given,
-- and w:from_mesh(m, {tets = true, young}) builds Neo-Hookean tets without links.

local function scene()
  local w = wobble.world{ gravity = { 0.2, -9.81, 0 }, substeps = 6 }
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0 }
  w:lattice{ min = { -0.3, 0.2, -0.3 }, max = { 0.3, 0.8, 0.3 }, res = { 3, 4, 3 }, tets = true,
             young = 2e4, poisson = 0.35 }
  local p = { w:particle{ pos = { 1, 1, 0 } }, w:particle{ pos = { 2, 1, 0 }, mass = 2 },
              w:particle{ pos = { 1, 2, 0 } }, w:particle{ pos = { 1, 1, 1 } } }
  w:tet(p[1], p[2], p[3], p[4], { young = 1e3, poisson = 0.1 })
  return w
end

test("w:save / wobble.load keep the tets: same hash, same future", function()
  local w = scene()
  for _ = 1, 20 do w:step() end
  assert(w:save("neo_io/snap.json"))
  local c = assert(wobble.load("neo_io/snap.json"))
  expect.eq(c:hash(), w:hash(), "same state")
  expect.eq(c:tet_count(), w:tet_count())
  for i = 1, w:tet_count() do
    local j1, e1, v1 = w:tet_info(i)
    local j2, e2, v2 = c:tet_info(i)
    expect.eq(j2, j1, "det F of " .. i)
    expect.eq(e2, e1, "energy of " .. i)
    expect.eq(v2, v1, "rest volume of " .. i)
  end
  for _ = 1, 30 do w:step(); c:step() end
  expect.eq(c:hash(), w:hash(), "same future")
  -- and the in-memory copy (w:clone goes through the same image) when there is one
  if w.clone then
    local d = w:clone()
    for _ = 1, 10 do w:step(); d:step() end
    expect.eq(d:hash(), w:hash(), "clone: same future")
  end
end)

test("the future differs without the tets (the round trip test can fail)", function()
  local w = scene()
  for _ = 1, 20 do w:step() end
  assert(w:save("neo_io/snap2.json"))
  local f = assert(io.open("neo_io/snap2.json", "rb"))
  local text = f:read("a")
  f:close()
  local stripped, n = text:gsub('  "tets": %b[],\n', "")
  expect.eq(n, 1, "the snapshot has a tets section")
  f = assert(io.open("neo_io/snap3.json", "wb"))
  f:write(stripped)
  f:close()
  local c = assert(wobble.load("neo_io/snap3.json"))
  expect.eq(c:tet_count(), 0)
  expect.eq(c:hash(), w:hash(), "same state now")
  for _ = 1, 30 do w:step(); c:step() end
  expect.truthy(c:hash() ~= w:hash(), "a different future")
end)

test("a particle config's tets: rest state from the particles, errors named", function()
  local function load(tets)
    local f = assert(io.open("neo_io/tet.json", "wb"))
    f:write('{"format": "wobble-particles", "version": 1, "particles": [{"position": [0,0,0]}, {"position": [1,0,0]},',
            ' {"position": [0,1,0]}, {"position": [0,0,1]}], "tets": ', tets, '}')
    f:close()
    return wobble.load("neo_io/tet.json")
  end
  local w = assert(load('[{"particles": [0, 1, 2, 3], "young": 1e4}]'))
  expect.eq(w:tet_count(), 1)
  local j, e, v0 = w:tet_info(1)
  expect.near(j, 1, 1e-15, "at rest")
  expect.near(e, 0, 1e-12, "no energy at rest")
  expect.near(v0, 1 / 6, 1e-15, "rest volume")
  local c, err = load('[{"particles": [0, 1, 2, 3]}]')
  expect.eq(c, nil)
  expect.truthy(err:find("young"), err)
  c, err = load('[{"particles": [0, 1, 2, 3], "young": 1e4, "poisson": 0.5}]')
  expect.truthy(err and err:find("poisson"), err)
  c, err = load('[{"particles": [0, 1, 2, 2], "young": 1e4}]')
  expect.truthy(err and err:find("distinct"), err)
  c, err = load('[{"particles": [0, 1, 2, 3], "young": 1e4, "rest_volume": 1}]')
  expect.truthy(err and err:find("together"), err)
end)

test("w:from_mesh(m, {tets = true, young}): Neo-Hookean tets, no links", function()
  local m = wobble.load_mesh("../../assets/rounded_cube.obj")
  local w = wobble.world{}
  local b = w:from_mesh(m, { tets = true, young = 5e4, poisson = 0.3, max_volume = 0.01 })
  expect.truthy(b.tet_count > 0, "tets made")
  expect.eq(w:tet_count(), b.tet_count, "all Neo-Hookean")
  expect.eq(w:volume_count(), 0, "no volume constraints")
  expect.eq(b.constraint_count, 0, "no links")
  local w2 = wobble.world{}
  local b2 = w2:from_mesh(m, { tets = true, max_volume = 0.01 })
  expect.eq(w2:tet_count(), 0, "without young: volume constraints")
  expect.eq(w2:volume_count(), b2.tet_count)
  expect.error(function() w:from_mesh(m, { tets = true, poisson = 0.3 }) end, "needs young")
end)
