-- collide_mesh.lua: mesh colliders (w:collider{shape = "mesh"}): signed distance against
-- an analytic shape, two-sided open meshes, resting contact, friction and restitution
-- against the plane's, a moving mesh that pushes without tunnelling, snapshots, errors.

-- a closed icosahedron with circumradius 1, built from its 12 vertices (0, +-1, +-phi)
-- cyclically: the 20 faces are the triples of mutually adjacent vertices (edge 2 before
-- scaling), turned counter-clockwise seen from outside
local function icosahedron()
  local phi = (1 + math.sqrt(5)) / 2
  local R = math.sqrt(1 + phi * phi)
  local raw = {}
  for _, s1 in ipairs{ -1, 1 } do
    for _, s2 in ipairs{ -1, 1 } do
      raw[#raw + 1] = { 0, s1, s2 * phi }
      raw[#raw + 1] = { s1, s2 * phi, 0 }
      raw[#raw + 1] = { s2 * phi, 0, s1 }
    end
  end
  local v = {}
  for i, p in ipairs(raw) do v[i] = { p[1] / R, p[2] / R, p[3] / R } end
  local function d2(a, b) return (a[1] - b[1]) ^ 2 + (a[2] - b[2]) ^ 2 + (a[3] - b[3]) ^ 2 end
  local e2 = 4 / (R * R)
  local tris = {}
  for i = 1, 12 do for j = i + 1, 12 do for k = j + 1, 12 do
    if math.abs(d2(v[i], v[j]) - e2) < 1e-9 and math.abs(d2(v[j], v[k]) - e2) < 1e-9 and math.abs(d2(v[i], v[k]) - e2) < 1e-9 then
      local a, b, c = v[i], v[j], v[k]
      local u = { b[1] - a[1], b[2] - a[2], b[3] - a[3] }
      local w = { c[1] - a[1], c[2] - a[2], c[3] - a[3] }
      local n = { u[2] * w[3] - u[3] * w[2], u[3] * w[1] - u[1] * w[3], u[1] * w[2] - u[2] * w[1] }
      if n[1] * a[1] + n[2] * a[2] + n[3] * a[3] > 0 then tris[#tris + 1] = { i, j, k }
      else tris[#tris + 1] = { i, k, j } end
    end
  end end end
  return v, tris
end

-- distance from p to triangle (a, b, c), independent of the C code's region method: the
-- projection onto the plane when it falls inside (barycentric signs), else the nearest
-- of the three edges
local function sub(a, b) return { a[1] - b[1], a[2] - b[2], a[3] - b[3] } end
local function dot(a, b) return a[1] * b[1] + a[2] * b[2] + a[3] * b[3] end
local function cross(a, b) return { a[2] * b[3] - a[3] * b[2], a[3] * b[1] - a[1] * b[3], a[1] * b[2] - a[2] * b[1] } end
local function seg(p, a, b)
  local ab, ap = sub(b, a), sub(p, a)
  local t = math.max(0, math.min(1, dot(ap, ab) / dot(ab, ab)))
  local q = { a[1] + ab[1] * t, a[2] + ab[2] * t, a[3] + ab[3] * t }
  return math.sqrt(dot(sub(p, q), sub(p, q)))
end
local function tri_dist(p, a, b, c)
  local n = cross(sub(b, a), sub(c, a))
  local ln = math.sqrt(dot(n, n))
  n = { n[1] / ln, n[2] / ln, n[3] / ln }
  local h = dot(sub(p, a), n)
  local q = { p[1] - n[1] * h, p[2] - n[2] * h, p[3] - n[3] * h }
  local s1 = dot(cross(sub(b, a), sub(q, a)), n)
  local s2 = dot(cross(sub(c, b), sub(q, b)), n)
  local s3 = dot(cross(sub(a, c), sub(q, c)), n)
  if s1 >= 0 and s2 >= 0 and s3 >= 0 then return math.abs(h) end
  return math.min(seg(p, a, b), seg(p, b, c), seg(p, c, a))
end

-- the icosahedron's exact signed distance: convex, so inside it is minus the distance
-- to the nearest face plane, outside the distance to the nearest face
local function ico_distance(v, tris, p)
  local inside, best_plane, best = true, math.huge, math.huge
  for _, t in ipairs(tris) do
    local a, b, c = v[t[1]], v[t[2]], v[t[3]]
    local n = cross(sub(b, a), sub(c, a))
    local ln = math.sqrt(dot(n, n))
    local h = dot(sub(p, a), n) / ln
    if h > 0 then inside = false end
    best_plane = math.min(best_plane, -h)
    best = math.min(best, tri_dist(p, a, b, c))
  end
  if inside then return -best_plane end
  return best
end

test("a closed icosahedron's signed distance is the analytic one, its sign inside/outside the spheres", function()
  local v, tris = icosahedron()
  expect.eq(#tris, 20)
  local m = wobble.mesh{ vertices = v, triangles = tris }
  local w = wobble.world{}
  local col = w:collider{ shape = "mesh", mesh = m }
  -- the inscribed sphere: the faces' distance from the centre
  local r_in = -ico_distance(v, tris, {0, 0, 0})
  expect.near(r_in, 0.7946544722917661, 1e-12)
  local seed, worst, n_in, n_out = 12345, 0, 0, 0
  local function rnd() seed = (seed * 1103515245 + 12345) % 2147483648 return seed / 2147483648 end
  for _ = 1, 2000 do
    -- directions uniform-ish, radii from 0 to 2 so that every feature region is hit
    local p = { rnd() * 2 - 1, rnd() * 2 - 1, rnd() * 2 - 1 }
    local l = math.sqrt(dot(p, p))
    local r = rnd() * 2
    p = { p[1] / l * r, p[2] / l * r, p[3] / l * r }
    local d = col:distance(p[1], p[2], p[3])
    -- round-off of O(1) values over a few dozen operations: 1e-12 is 5000 ulps of slack
    worst = math.max(worst, math.abs(d - ico_distance(v, tris, p)))
    if r < r_in then expect.lt(d, 0, "inside the inscribed sphere is inside"); n_in = n_in + 1 end
    if r > 1 then expect.gt(d, 0, "outside the circumscribed sphere is outside"); n_out = n_out + 1 end
  end
  expect.lt(worst, 1e-12, "largest |distance - analytic| over 2000 points")
  expect.gt(n_in, 500); expect.gt(n_out, 800)
  -- on the vertices' sphere exactly at a vertex: distance 0
  expect.near(col:distance(v[1][1], v[1][2], v[1][3]), 0, 1e-15)
  -- moved and turned: distance follows the pose
  local s = math.sqrt(0.5)
  col:set_position(3, 0, 0); col:set_rotation(s, 0, s, 0)
  expect.near(col:distance(3, 0, 0), -r_in, 1e-12)
end)

local function quad(y)
  return wobble.mesh{ vertices = {{-1, y, -1}, {1, y, -1}, {1, y, 1}, {-1, y, 1}}, triangles = {{1, 3, 2}, {1, 4, 3}} }
end

test("an open mesh (a quad) is two-sided: distance >= 0 on both sides, particles kept on their side", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local col = w:collider{ shape = "mesh", mesh = quad(0) }
  expect.near(col:distance(0.3, 0.5, 0.2), 0.5, 1e-15)
  expect.near(col:distance(0.3, -0.5, 0.2), 0.5, 1e-15)
  expect.near(col:distance(2, 0, 0), 1, 1e-15)
  -- one particle from above, one from below, both thrown at the sheet fast enough to
  -- cross it within one substep (0.03 m per substep > the radius 0.01): each stays on
  -- its own side, at its radius
  local a = w:particle{ pos = {0, 0.02, 0}, vel = {0, -18, 0}, radius = 0.01 }
  local b = w:particle{ pos = {0.5, -0.02, 0}, vel = {0, 18, 0}, radius = 0.01 }
  w:run{ frames = 10 }
  local _, ya = w:position(a)
  local _, yb = w:position(b)
  expect.near(ya, 0.01, 1e-9, "from above: rests above")
  expect.near(yb, -0.01, 1e-9, "from below: rests below")
end)

test("a particle dropped on a mesh floor rests on it at its radius", function()
  local w = wobble.world{}
  w:collider{ shape = "mesh", mesh = quad(0), scale = 3 }
  local p = w:particle{ pos = {0.2, 1, 0.1}, radius = 0.05 }
  local lowest = math.huge
  w:run{ seconds = 2, on_frame = function(w) local _, y = w:position(p) lowest = math.min(lowest, y) end }
  local x, y, z = w:position(p)
  -- the projection puts it exactly at its radius each substep: only round-off remains
  expect.near(y, 0.05, 1e-9)
  expect.gt(lowest, 0.05 - 1e-9, "never below its radius at a frame's end")
  expect.near(x, 0.2, 1e-12); expect.near(z, 0.1, 1e-12)
  local _, vy = w:velocity(p)
  expect.lt(math.abs(vy), 1e-6, "at rest")
end)

-- the same throw onto a plane collider and onto a mesh floor of the same material:
-- the contact normal, depth and surface velocity are the same, so the trajectories
-- agree to round-off (the plane's depth is r + offset - n.x, the mesh's r - |x - c|)
local function throw(shape, friction, restitution)
  local w = wobble.world{}
  if shape == "plane" then
    w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = friction, restitution = restitution }
  else
    w:collider{ shape = "mesh", mesh = quad(0), scale = 50, friction = friction, restitution = restitution }
  end
  local p = w:particle{ pos = {0, 0.5, 0}, vel = {3, 1, 1}, radius = 0.03 }
  local path = {}
  w:run{ frames = 120, on_frame = function(w) path[#path + 1] = { w:position(p) } end }
  return path
end

test("restitution and friction behave as the plane's in the same throw", function()
  for _, mat in ipairs{ { 0, 0 }, { 0.4, 0 }, { 0, 0.7 }, { 0.3, 0.5 }, { 2, 1 } } do
    local a, b = throw("plane", mat[1], mat[2]), throw("mesh", mat[1], mat[2])
    local worst = 0
    for i = 1, #a do
      for k = 1, 3 do worst = math.max(worst, math.abs(a[i][k] - b[i][k])) end
    end
    expect.lt(worst, 1e-9, string.format("friction %g, restitution %g: largest difference", mat[1], mat[2]))
  end
  -- and the materials do something: with friction the particle ends nearer its start
  local slide, stick = throw("mesh", 0, 0), throw("mesh", 0.5, 0)
  expect.gt(slide[#slide][1], stick[#stick][1] + 0.5)
  local bouncy = throw("mesh", 0, 0.8)
  local dead = throw("mesh", 0, 0)
  local top_b, top_d = 0, 0
  for i = 40, 120 do top_b = math.max(top_b, bouncy[i][2]); top_d = math.max(top_d, dead[i][2]) end
  expect.gt(top_b, top_d + 0.1, "restitution bounces")
end)

-- a closed cube mesh of half size h
local function cube(h)
  local v = {}
  for i = 0, 7 do v[i + 1] = { (i & 1 == 1) and h or -h, (i & 2 == 2) and h or -h, (i & 4 == 4) and h or -h } end
  local quads = { {1, 3, 4, 2}, {5, 6, 8, 7}, {1, 2, 6, 5}, {3, 7, 8, 4}, {1, 5, 7, 3}, {2, 4, 8, 6} }
  local t = {}
  for _, q in ipairs(quads) do t[#t + 1] = { q[1], q[2], q[3] }; t[#t + 1] = { q[1], q[3], q[4] } end
  return wobble.mesh{ vertices = v, triangles = t }
end

test("a cube mesh is closed: inside negative, outside its box distance", function()
  local w = wobble.world{}
  local col = w:collider{ shape = "mesh", mesh = cube(0.5) }
  expect.near(col:distance(0, 0, 0), -0.5, 1e-15)
  expect.near(col:distance(0.2, 0.4, 0), -0.1, 1e-15)
  expect.near(col:distance(1, 1, 0.5), math.sqrt(0.5), 1e-15)
end)

test("a moving mesh collider (set_velocity) pushes particles ahead of it without tunnelling", function()
  local w = wobble.world{ gravity = {0, 0, 0} }
  local col = w:collider{ shape = "mesh", mesh = cube(0.1), center = {-1, 0, 0} }
  -- 30 m/s: 0.5 m per frame, five times the cube's size; 0.05 m per substep
  col:set_velocity(30, 0, 0)
  local ps = {}
  for i = 1, 5 do ps[i] = w:particle{ pos = {i * 0.3, 0.05 * (i - 3) / 2, 0}, radius = 0.01 } end
  w:run{ frames = 10 }
  local cx = col:position()
  expect.near(cx, 4, 1e-9)
  for i, p in ipairs(ps) do
    local x = w:position(p)
    expect.gt(x, cx + 0.1 + 0.01 - 1e-6, "particle " .. i .. " is ahead of the cube's front face")
  end
end)

test("a snapshot round-trips a mesh collider: same hash, same future, same distances", function()
  local r = wobble.load_mesh("../../assets/rounded_cube.obj")
  local w = wobble.world{}
  local col = w:collider{ shape = "mesh", mesh = r, center = {0, 0.5, 0}, rotation = {0.9, 0.1, 0.2, 0.3},
                          scale = 1.3, friction = 0.2, restitution = 0.1 }
  col:set_velocity(0.1, 0, 0)
  for i = 1, 20 do w:particle{ pos = {i * 0.05 - 0.5, 1.5, 0.01 * i}, radius = 0.02 } end
  w:run{ frames = 20 }
  w:save("collide_mesh/snap.json")
  local w2 = wobble.load("collide_mesh/snap.json")  -- a relative path: inside the output folder
  expect.eq(w2:hash(), w:hash())
  local c2 = w2:colliders()[1]
  expect.eq(c2:shape(), "mesh")
  for _, p in ipairs{ {0, 0.5, 0}, {1, 2, 0.3}, {0.2, 0.9, -0.1} } do
    expect.eq(c2:distance(p[1], p[2], p[3]), col:distance(p[1], p[2], p[3]))
  end
  expect.eq(select(1, c2:material()), 0.2)
  w:run{ frames = 20 }; w2:run{ frames = 20 }
  expect.eq(w2:hash(), w:hash())
end)

test("mesh collider errors name the key and add nothing", function()
  local w = wobble.world{}
  expect.error(function() w:collider{ shape = "mesh" } end, "field 'mesh': missing")
  expect.error(function() w:collider{ shape = "mesh", mesh = 3 } end, "field 'mesh': mesh expected, got number")
  local empty = wobble.mesh{ vertices = {{0, 0, 0}}, triangles = {} }
  expect.error(function() w:collider{ shape = "mesh", mesh = empty } end, "field 'mesh': is empty")
  expect.error(function() w:collider{ shape = "mesh", mesh = quad(0), scale = 0 } end, "scale must be > 0")
  expect.error(function() w:collider{ shape = "mesh", mesh = quad(0), scale = -2 } end, "scale must be > 0")
  expect.error(function() w:collider{ shape = "mesh", mesh = quad(0), rotation = {0, 0, 0, 0} } end, "rotation must not be zero")
  expect.error(function() w:collider{ shape = "mesh", mesh = quad(0), radius = 1 } end, "unknown key 'radius'")
  expect.error(function() w:collider{ shape = "sphere", mesh = quad(0) } end, "unknown key 'mesh'")
  expect.error(function() w:collider{ shape = "mesh", mesh = quad(10), scale = 1e308 } end, "finite")
  local closed = quad(0); closed:close()
  expect.error(function() w:collider{ shape = "mesh", mesh = closed } end, "mesh is closed")
  expect.eq(#w:colliders(), 0)
end)

local function write(name, text)
  local f = assert(io.open(name, "w"))
  f:write(text)
  f:close()
  return name
end

test("a JSON particle config lists a mesh collider in the world form; bad corners name the key path", function()
  local w = wobble.world{}
  local b = assert(w:load_particles(write("collide_mesh/cfg.json", [[
{"format": "wobble-particles", "version": 1, "particles": [{"position": [0, 2, 0]}],
 "colliders": [{"shape": "mesh", "vertices": [-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1],
                "triangles": [0, 2, 1, 0, 3, 2], "center": [0, 0.5, 0], "scale": 2, "friction": 0.3}]}]])))
  local col = b.colliders[1]
  expect.eq(col:shape(), "mesh")
  expect.near(col:distance(0, 2, 0), 1.5, 1e-15)
  expect.near(col:distance(2.5, 0.5, 0), 0.5, 1e-15)   -- scale 2: the quad reaches x = 2
  expect.eq(select(1, col:material()), 0.3)
  -- the same through w:collider gives the same distances
  local c2 = w:collider{ shape = "mesh", mesh = quad(0), center = {0, 0.5, 0}, scale = 2 }
  expect.eq(c2:distance(0.3, 1.7, -0.4), col:distance(0.3, 1.7, -0.4))
  local n = #w:colliders()
  local ok, err = w:load_particles(write("collide_mesh/bad.json", [[
{"format": "wobble-particles", "version": 1, "particles": [],
 "colliders": [{"shape": "mesh", "vertices": [0, 0, 0, 1, 0, 0, 0, 0, 1], "triangles": [0, 1, 3]}]}]]))
  expect.eq(ok, nil)
  expect.truthy(err:find("colliders%[1%]%.triangles%[3%]") or err:find("triangles"), err)
  local ok2, err2 = w:load_particles(write("collide_mesh/bad2.json", [[
{"format": "wobble-particles", "version": 1, "particles": [],
 "colliders": [{"shape": "mesh", "vertices": [0, 0, 0, 1, 0, 0, 0, 0, 1], "triangles": [0, 1, 2], "radius": 1}]}]]))
  expect.eq(ok2, nil)
  expect.truthy(err2:find("radius"), err2)
  expect.eq(#w:colliders(), n, "a refused config adds nothing")
end)
