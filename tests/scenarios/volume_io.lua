-- volume_io.lua: volume constraints and tet solids in and out of files, and tetgen.
--
-- Snapshots: w:save / wobble.load keep every volume constraint (corners, compliance,
-- signed rest) exactly: the same w:hash() (which covers positions and velocities) and
-- the same future, which a lost or changed constraint would not give (checked: the
-- copy without its volumes drifts from the original). Particle configs take a
-- "volumes" array (rest defaults to the particles' current signed volume).
--
-- tetgen: a closed mesh is filled so that the tets' volumes add up to the volume the
-- mesh encloses (divergence theorem over its triangles). With the surface kept (the
-- default, tetgen -Y) the tets fill exactly the mesh's polyhedron, so the two agree to
-- round-off of ~1e5 tets of size ~1e-5 m^3 (1e-9 relative is asked); with the surface
-- refined (keep_surface = false) tetgen adds points on the facets, on them only up to its
-- coplanarity tolerance (-T, 1e-8 relative): 1e-7 is asked (measured 6e-9 on the torus). An open mesh is refused before tetgen runs, naming an open edge; one
-- that crosses itself is refused with tetgen's own finding. .node/.ele round trip: the
-- positions are written with 17 digits, so they come back bit for bit.

local function enclosed(m)
  local v = 0
  for t = 1, m:triangle_count() do
    local a, b, c = m:triangle(t)
    local p, q, r = { m:vertex(a) }, { m:vertex(b) }, { m:vertex(c) }
    v = v + (p[1] * (q[2] * r[3] - q[3] * r[2]) - p[2] * (q[1] * r[3] - q[3] * r[1]) +
             p[3] * (q[1] * r[2] - q[2] * r[1])) / 6
  end
  return v
end

local PTS = { {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1} }
local FACES = { {1, 3, 2}, {1, 4, 3}, {5, 6, 7}, {5, 7, 8}, {1, 2, 6}, {1, 6, 5},
                {2, 3, 7}, {2, 7, 6}, {3, 4, 8}, {3, 8, 7}, {4, 1, 5}, {4, 5, 8} }

local function scene()
  local w = wobble.world{ gravity = { 0.2, -9.81, 0 }, substeps = 6 }
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0 }
  w:lattice{ min = { -0.3, 0.2, -0.3 }, max = { 0.3, 0.8, 0.3 }, res = { 3, 4, 3 }, compliance = 1e-3,
             tets = true, volume_compliance = 1e-7 }
  local p = { w:particle{ pos = { 1, 1, 0 } }, w:particle{ pos = { 2, 1, 0 }, mass = 2 },
              w:particle{ pos = { 1, 2, 0 } }, w:particle{ pos = { 1, 1, 1 } } }
  w:volume(p[1], p[2], p[3], p[4], { rest = 0.3, compliance = 1e-6 })
  return w
end

test("w:save / wobble.load keep the volume constraints: same hash, same future", function()
  local w = scene()
  for _ = 1, 20 do w:step() end
  assert(w:save("volume_io/snap.json"))
  local c = assert(wobble.load("volume_io/snap.json"))
  expect.eq(c:hash(), w:hash(), "same state")
  expect.eq(c:volume_count(), w:volume_count())
  for i = 1, w:volume_count() do
    local _, r1 = w:volume_info(i)
    local _, r2 = c:volume_info(i)
    expect.eq(r2, r1, "rest of " .. i)
  end
  for _ = 1, 30 do w:step(); c:step() end
  expect.eq(c:hash(), w:hash(), "same future")
end)

test("the future differs without the volumes (the round trip test can fail)", function()
  local w = scene()
  for _ = 1, 20 do w:step() end
  assert(w:save("volume_io/snap2.json"))
  local f = assert(io.open("volume_io/snap2.json", "rb"))
  local text = f:read("a")
  f:close()
  local stripped, n = text:gsub('  "volumes": %b[],\n', "")
  expect.eq(n, 1, "the snapshot has a volumes section")
  f = assert(io.open("volume_io/snap3.json", "wb"))
  f:write(stripped)
  f:close()
  local c = assert(wobble.load("volume_io/snap3.json"))
  expect.eq(c:volume_count(), 0)
  expect.eq(c:hash(), w:hash(), "same state now")
  for _ = 1, 30 do w:step(); c:step() end
  expect.truthy(c:hash() ~= w:hash(), "a different future")
end)

test("a particle config's volumes: rest defaults to the current signed volume", function()
  local f = assert(io.open("volume_io/tet.json", "wb"))
  f:write([[{"format": "wobble-particles", "version": 1,
    "particles": [{"position": [0, 0, 0]}, {"position": [1, 0, 0]}, {"position": [0, 1, 0]}, {"position": [0, 0, 1]}],
    "volumes": [{"particles": [0, 1, 2, 3]}, {"particles": [0, 2, 1, 3], "rest": 0.5, "compliance": 1e-3}]}]])
  f:close()
  local w = wobble.world{}
  local b = assert(w:load_particles("volume_io/tet.json"))
  expect.eq(b.count, 4)
  expect.eq(w:volume_count(), 2)
  local v, rest = w:volume_info(1)
  expect.near(rest, 1 / 6, 1e-15); expect.near(v, 1 / 6, 1e-15)
  v, rest = w:volume_info(2)
  expect.near(v, -1 / 6, 1e-15, "corners swapped: negative"); expect.eq(rest, 0.5)
  f = assert(io.open("volume_io/bad.json", "wb"))
  f:write([[{"format": "wobble-particles", "version": 1,
    "particles": [{"position": [0, 0, 0]}, {"position": [1, 0, 0]}, {"position": [0, 1, 0]}],
    "volumes": [{"particles": [0, 1, 2, 1]}]}]])
  f:close()
  local ok, err = w:load_particles("volume_io/bad.json")
  expect.eq(ok, nil)
  expect.truthy(err:find("volumes%[0%]%.particles") and err:find("four distinct"), err)
  expect.eq(w:volume_count(), 2, "nothing added")
end)

test("tetgen fills a closed mesh: the tets' volume is the enclosed volume", function()
  local m = wobble.load_mesh("../../assets/rounded_cube.obj")
  local w = wobble.world{}
  local b = w:from_mesh(m, { tets = true, max_volume = 0.002 })
  local v = enclosed(m)
  local cur, rest = w:total_volume()
  expect.rel(rest, v, 1e-9, "rest volume = enclosed volume")
  expect.rel(cur, v, 1e-9)
  expect.eq(b.tet_count, w:volume_count())
  expect.gt(b.count, m:vertex_count(), "interior particles were added")
  -- the largest tet respects max_volume
  local big = 0
  for i = 1, w:volume_count() do big = math.max(big, select(2, w:volume_info(i))) end
  expect.le(big, 0.002 * (1 + 1e-9), "max_volume")
  -- the surface kept: the mesh's vertices are the first particles, where they were
  for i = 1, m:vertex_count(), 97 do
    local x, y, z = m:vertex(i)
    local px, py, pz = w:position(b.first + i - 1)
    expect.eq(px, x); expect.eq(py, y); expect.eq(pz, z)
  end
  -- a torus (genus 1), its surface refined by tetgen
  local t = wobble.load_mesh("../../assets/torus.ply")
  local w2 = wobble.world{}
  w2:from_mesh(t, { tets = true, keep_surface = false, quality = 1.5 })
  expect.rel((w2:total_volume()), enclosed(t), 1e-7, "torus")
  for i = 1, w2:volume_count() do expect.gt(select(2, w2:volume_info(i)), 0, "positive tets") end
end)

test("tetgen refuses an open mesh and one that crosses itself, clearly", function()
  local w = wobble.world{}
  local open = {}
  for i = 1, 11 do open[i] = FACES[i] end
  expect.error(function() w:from_mesh(wobble.mesh{ vertices = PTS, triangles = open }, { tets = true }) end,
               "the mesh is not closed: 3 edge")
  local P, F = {}, {}
  for i, p in ipairs(PTS) do P[i] = p; P[i + 8] = { p[1] + 0.5, p[2] + 0.5, p[3] + 0.5 } end
  for i, f in ipairs(FACES) do F[i] = f; F[i + 12] = { f[1] + 8, f[2] + 8, f[3] + 8 } end
  print("expected on stderr: nothing (tetgen's abort goes to its own log)")
  expect.error(function() w:from_mesh(wobble.mesh{ vertices = P, triangles = F }, { tets = true }) end,
               "the mesh intersects itself")
  expect.eq(w:particle_count(), 0, "nothing made")
  expect.error(function() w:from_mesh(wobble.mesh{ vertices = PTS, triangles = FACES }, { tets = true, quality = 0.5 }) end,
               "quality")
  expect.error(function() w:from_mesh(wobble.mesh{ vertices = PTS, triangles = FACES }, { tets = true, target = 3 }) end,
               "target")
end)

test(".node/.ele round trip, and load_tets makes the same solid", function()
  local w = wobble.world{ gravity = { 0, 0, 0 } }
  local b = w:from_mesh(wobble.mesh{ vertices = PTS, triangles = FACES }, { tets = true, max_volume = 0.05,
                                                                            keep_surface = false })
  w:particle{ pos = { 5, 5, 5 } } -- not in the body: left out
  assert(w:save_tets("volume_io/cube", b))
  local w2 = wobble.world{ gravity = { 0, 0, 0 } }
  local b2 = assert(w2:load_tets("volume_io/cube.node"))
  expect.eq(b2.count, b.count); expect.eq(b2.tet_count, b.tet_count)
  for i = 0, b.count - 1 do
    local x, y, z = w:position(b.first + i)
    local u, v, s = w2:position(b2.first + i)
    expect.eq(u, x); expect.eq(v, y); expect.eq(s, z)
  end
  for i = 1, w:volume_count() do
    local _, r1 = w:volume_info(i)
    local _, r2 = w2:volume_info(i)
    expect.eq(r2, r1, "tet " .. i)
  end
  expect.rel((w2:total_volume()), 1, 1e-12, "a unit cube")
  expect.eq(b2.constraint_count, b.constraint_count, "a link per tet edge")
  -- errors name the file and line
  local f = assert(io.open("volume_io/broken.node", "wb"))
  f:write("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n")
  f:close()
  f = assert(io.open("volume_io/broken.ele", "wb"))
  f:write("1 4 0\n1 1 2 3 4\n")
  f:close()
  local ok, err = w2:load_tets("volume_io/broken")
  expect.eq(ok, nil)
  expect.truthy(err:find("broken.node: 4 points announced, 3 found", 1, true), err)
  f = assert(io.open("volume_io/broken.node", "wb"))
  f:write("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n")
  f:close()
  f = assert(io.open("volume_io/broken.ele", "wb"))
  f:write("# a comment\n1 4 0\n1 1 2 3 5\n")
  f:close()
  ok, err = w2:load_tets("volume_io/broken")
  expect.eq(ok, nil)
  expect.truthy(err:find("broken.ele:3: node 5 out of range", 1, true), err)
  ok, err = w2:load_tets("volume_io/missing")
  expect.eq(ok, nil)
  expect.truthy(err:find("missing.node", 1, true), err)
  expect.error(function() w2:load_tets("/etc/passwd") end, "passwd")
end)

test("from_mesh's tets options refuse unknown keys and non-finite numbers, changing nothing", function()
  local w = wobble.world{}
  local m = wobble.mesh{ vertices = PTS, triangles = FACES }
  expect.error(function() w:from_mesh(m, { tets = true, no_such_key = 1 }) end, "unknown key 'no_such_key'")
  for _, key in ipairs{ "max_volume", "quality", "timeout", "mass", "radius", "volume_compliance", "compliance" } do
    for _, bad in ipairs{ 0 / 0, 1 / 0, -1 / 0 } do
      expect.error(function() w:from_mesh(m, { tets = true, [key] = bad }) end, key)
    end
  end
  expect.error(function() w:from_mesh(m, { tets = true, max_volume = 0 }) end, "max_volume")
  expect.eq(w:particle_count(), 0, "nothing made")
  -- the valid call works, with every option
  local b = w:from_mesh(m, { tets = true, max_volume = 0.2, quality = 2, keep_surface = true, timeout = 30, mass = 2,
                             radius = 0.01, volume_compliance = 1e-6, compliance = 1e-4, damping = 0, collide = true })
  expect.eq(w:mass(b.first) > 0, true)
  local total = 0
  for i = b.first, b.first + b.count - 1 do total = total + w:mass(i) end
  expect.near(total, 2, 1e-12, "mass lumped by volume adds up")
end)
