-- export_pc2.lua: PC2 point caches for Blender's Mesh Cache modifier, with the rest-pose
-- mesh beside them (same vertex order): of a skin (s:record_pc2) or of particles
-- (w:record_pc2). The file is read back here byte by byte.

local function read(name)
  local f = assert(io.open(name, "rb"))
  local s = f:read("a")
  f:close()
  return s
end

-- header fields and the samples as {{x,y,z}, ...} per sample
local function pc2(name)
  local s = read(name)
  local sig, version, n, start, rate, samples, pos = string.unpack("<c12i4i4ffi4", s)
  local frames = {}
  for k = 1, samples do
    local f = {}
    for i = 1, n do
      local x, y, z
      x, y, z, pos = string.unpack("<fff", s, pos)
      f[i] = { x, y, z }
    end
    frames[k] = f
  end
  return { sig = sig, version = version, n = n, start = start, rate = rate, samples = samples,
           frames = frames, size = #s }
end

local function cube_mesh()
  local v, t = {}, {}
  local n = 6 -- a 6 x 6 grid per face, welded at the edges on load
  for face = 0, 5 do
    local a, s = face // 2, face % 2 == 0 and -1 or 1
    local u, w = (a + 1) % 3, (a + 2) % 3
    local base = #v
    for j = 0, n do
      for i = 0, n do
        local p = {}
        p[a + 1], p[u + 1], p[w + 1] = 0.5 + 0.4 * s, 0.1 + 0.8 * i / n, 0.1 + 0.8 * j / n
        v[#v + 1] = p
      end
    end
    for j = 0, n - 1 do
      for i = 0, n - 1 do
        local k = base + j * (n + 1) + i + 1
        if s > 0 then
          t[#t + 1] = { k, k + 1, k + n + 2 }; t[#t + 1] = { k, k + n + 2, k + n + 1 }
        else
          t[#t + 1] = { k, k + n + 2, k + 1 }; t[#t + 1] = { k, k + n + 1, k + n + 2 }
        end
      end
    end
  end
  return wobble.mesh{ vertices = v, triangles = t, weld = true }
end

test("a skin's point cache: header, samples, rest mesh", function()
  local w = wobble.world{ substeps = 10 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = -0.5 }
  local cage = w:lattice{ min = {0, 0, 0}, max = {1, 1, 1}, res = {3, 3, 3}, compliance = 1e-4 }
  local m = cube_mesh()
  local s = w:skin(m, cage)
  local rec = s:record_pc2("export_pc2/cube.pc2")
  expect.eq(rec:frames(), 1, "the pose now is the first sample")
  w:run{ frames = 24 }
  expect.eq(rec:frames(), 25)
  local last = { s:vertex(m:vertex_count()) }
  expect.eq(rec:close(), true)
  expect.eq(rec:close(), true, "twice is fine")
  expect.eq(rec:closed(), true)
  local c = pc2("export_pc2/cube.pc2")
  expect.eq(c.sig, "POINTCACHE2\0")
  expect.eq(c.version, 1)
  expect.eq(c.n, m:vertex_count())
  expect.eq(c.start, 0)
  expect.eq(c.rate, 1)
  expect.eq(c.samples, 25)
  expect.eq(c.size, 32 + 25 * c.n * 12)
  -- the first sample is the rest mesh, the last the skin now (float32)
  for i = 1, c.n, 17 do
    local x, y, z = m:vertex(i)
    expect.near(c.frames[1][i][1], x, 1e-6); expect.near(c.frames[1][i][2], y, 1e-6); expect.near(c.frames[1][i][3], z, 1e-6)
  end
  for k = 1, 3 do expect.near(c.frames[25][c.n][k], last[k], 1e-6) end
  expect.lt(c.frames[25][1][2], c.frames[1][1][2] - 0.1, "it fell")
  -- the rest mesh beside it: same vertices, same order
  local obj = read("export_pc2/cube.obj")
  local i = 0
  for x, y, z in obj:gmatch("\nv (%S+) (%S+) (%S+)") do
    i = i + 1
    local ex, ey, ez = m:vertex(i)
    expect.near(tonumber(x), ex, 1e-8); expect.near(tonumber(y), ey, 1e-8); expect.near(tonumber(z), ez, 1e-8)
  end
  expect.eq(i, m:vertex_count())
end)

test("every = k, a PLY rest mesh, and no rest mesh", function()
  local w = wobble.world{}
  local b = w:rope{ from = {0, 1, 0}, to = {1, 1, 0}, segments = 4 }
  w:pin(b.first)
  local rec = assert(w:record_pc2("export_pc2/rope.pc2", { particles = b, every = 5, rest = "ply" }))
  w:run{ frames = 12 }
  expect.eq(rec:frames(), 3) -- now, after frame 5, after frame 10
  rec:close()
  local c = pc2("export_pc2/rope.pc2")
  expect.eq(c.n, 5)
  expect.eq(c.samples, 3)
  expect.eq(c.rate, 5) -- frames per sample
  expect.truthy(read("export_pc2/rope.ply"):find("^ply\nformat ascii 1.0\n"))
  local r2 = assert(w:record_pc2("export_pc2/norest.pc2", { rest = false }))
  r2:close()
  expect.eq(pc2("export_pc2/norest.pc2").rate, 1)
  expect.eq(io.open("export_pc2/norest.obj"), nil)
  -- a skin's cache too: {every = 3} is a sample rate of 3
  local m = wobble.mesh{ vertices = { {0, 1, 0}, {1, 1, 0}, {0.5, 1.5, 0} }, triangles = { {1, 2, 3} } }
  local s3 = w:skin(m, b, { bones = 2 })
  local r3 = assert(s3:record_pc2("export_pc2/skin3.pc2", { every = 3, rest = false }))
  r3:close()
  local c3 = pc2("export_pc2/skin3.pc2")
  expect.eq(c3.rate, 3)
  expect.eq(c3.start, w:frame())
  expect.eq(pc2("export_pc2/norest.pc2").n, w:particle_count())
end)

test("a recorder follows its own world only, and survives being dropped", function()
  local a, b = wobble.world{}, wobble.world{}
  a:particle{ pos = {0, 0, 0} }
  b:particle{ pos = {0, 0, 0} }
  os.remove("export_pc2/a.pc2")
  local rec = a:record_pc2("export_pc2/a.pc2")
  b:run{ frames = 5 }
  expect.eq(rec:frames(), 1)
  a:run{ frames = 2 }
  expect.eq(rec:frames(), 3)
  -- the cache grows beside its name and takes it when the recorder closes (r:close(),
  -- or the end of the run: its frame hook keeps a dropped recorder going)
  expect.eq(io.open("export_pc2/a.pc2"), nil)
  rec = nil
  collectgarbage()
  a:step()
end)

test("bad arguments", function()
  local w = wobble.world{}
  expect.error(function() w:record_pc2("export_pc2/empty.pc2") end, "the world has no particles to record")
  w:particle{ pos = {0, 0, 0} }
  expect.error(function() w:record_pc2("export_pc2/x.pc2", { every = 0 }) end, "field 'every': 0 out of range")
  expect.error(function() w:record_pc2("export_pc2/x.pc2", { rest = "stl" }) end, "unknown rest-pose format 'stl' (expected obj or ply)")
  expect.error(function() w:record_pc2("export_pc2/x.pc2", { particles = { 7 } }) end, "particle id 7 out of range")
  expect.error(function() w:record_pc2("/tmp/wobble-never.pc2") end, "is outside the output folder")
  local s = w:skin(wobble.mesh{ vertices = { {0, 0, 0} }, triangles = {} }, { 1 })
  expect.error(function() s:record_pc2("export_pc2/s.pc2", { particles = { 1 } }) end, "a skin records its own vertices")
  local rec = s:record_pc2("export_pc2/s.pc2")
  s:close()
  expect.error(function() w:step() end, "recording export_pc2/s.pc2: its skin was closed")
  expect.eq(rec:closed(), true)
  w:step() -- the failed recorder stays out of the way
  expect.truthy(tostring(rec):match("^wobble%.recorder: .+ %(PC2 export_pc2/s%.pc2, closed%)$"), tostring(rec))
end)
