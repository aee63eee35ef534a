-- penetration.lua: particles never end a frame inside a collider.
--
-- Particles of radius r falling onto, resting on, or pushed by plane, sphere, box and
-- capsule colliders: at the end of every frame the signed distance from each particle
-- centre to the collider surface must be >= r - eps. The signed distances are computed
-- here from the shapes' definitions (not with the collider's own distance query).
--
-- Why eps can be tiny: the collision projection is the last position update of every
-- substep (after the constraints) and puts a penetrating particle at distance exactly r
-- along the surface normal, up to round-off of its coordinates (~1e-16 relative, a few
-- 1e-16 m here). Static friction then undoes the tangential slip, a move within the
-- tangent plane at the contact, which for a convex shape cannot bring the particle
-- closer (the tangent plane supports the shape). A moving collider is at its final
-- pose in the last substep, up to the last bit of the interpolation. One collider per
-- world, so no projection undoes another. eps = 1e-10 m covers round-off with margin.

local eps = 1e-10

-- quaternion (w, x, y, z) rotating v, and its inverse
local function qrot(q, v, inv)
  local w, ux, uy, uz = q[1], q[2], q[3], q[4]
  if inv then ux, uy, uz = -ux, -uy, -uz end
  -- t = u x v + w v; v + 2 u x t
  local tx = uy * v[3] - uz * v[2] + w * v[1]
  local ty = uz * v[1] - ux * v[3] + w * v[2]
  local tz = ux * v[2] - uy * v[1] + w * v[3]
  return { v[1] + 2 * (uy * tz - uz * ty), v[2] + 2 * (uz * tx - ux * tz), v[3] + 2 * (ux * ty - uy * tx) }
end

local function len(a) return math.sqrt(a[1] ^ 2 + a[2] ^ 2 + a[3] ^ 2) end

-- signed distances from the shape definitions
local sdf = {}
function sdf.plane(s, p) -- n.x = offset, any |n|
  local n = len(s.normal)
  return (s.normal[1] * p[1] + s.normal[2] * p[2] + s.normal[3] * p[3] - s.offset) / n
end
function sdf.sphere(s, p, c)
  return len{ p[1] - c[1], p[2] - c[2], p[3] - c[3] } - s.radius
end
function sdf.box(s, p, c, q)
  local l = qrot(q, { p[1] - c[1], p[2] - c[2], p[3] - c[3] }, true)
  local d = { math.abs(l[1]) - s.half[1], math.abs(l[2]) - s.half[2], math.abs(l[3]) - s.half[3] }
  local o = { math.max(d[1], 0), math.max(d[2], 0), math.max(d[3], 0) }
  return len(o) + math.min(math.max(d[1], d[2], d[3]), 0)
end
function sdf.capsule(s, p, c) -- c: the collider's displacement since creation
  local a = { s.a[1] + c[1], s.a[2] + c[2], s.a[3] + c[3] }
  local ab = { s.b[1] - s.a[1], s.b[2] - s.a[2], s.b[3] - s.a[3] }
  local ap = { p[1] - a[1], p[2] - a[2], p[3] - a[3] }
  local t = (ap[1] * ab[1] + ap[2] * ab[2] + ap[3] * ab[3]) / (ab[1] ^ 2 + ab[2] ^ 2 + ab[3] ^ 2)
  t = math.max(0, math.min(1, t))
  return len{ ap[1] - t * ab[1], ap[2] - t * ab[2], ap[3] - t * ab[3] } - s.radius
end

-- a rain of particles of mixed radii over [x0,x1] x [z0,z1] at heights y0..y0+1
local function rain(w, x0, x1, y0, z0, z1, n)
  local ids = {}
  for i = 0, n - 1 do
    for k = 0, n - 1 do
      local r = 0.01 + 0.04 * ((i * 7 + k * 3) % 5) / 4
      local x = x0 + (x1 - x0) * (i + 0.5) / n
      local z = z0 + (z1 - z0) * (k + 0.5) / n
      ids[#ids + 1] = w:particle{ pos = { x, y0 + ((i + k) % 4) * 0.25, z }, mass = 0.1, radius = r,
                                  vel = { 0, -2 * ((i * k) % 3), 0 } }
    end
  end
  return ids
end

-- run `frames`, check every particle at every frame end; returns the worst
-- (distance - radius) seen and the number of contacts in the last step
local function watch(w, col, shape, def, frames, c0)
  local worst, n = math.huge, w:particle_count()
  w:run{ frames = frames, on_frame = function(w)
    local c = { col:position() }
    local q = { col:rotation() }
    if c0 then c = { c[1] - c0[1], c[2] - c0[2], c[3] - c0[3] } end
    for id = 1, n do
      local d = sdf[shape](def, { w:position(id) }, c, q) - w:radius(id)
      if d < worst then worst = d end
    end
  end }
  return worst, w:stats().contacts
end

test("plane: tilted, with friction and restitution; particles and a cloth land on it", function()
  local w = wobble.world{}
  local def = { shape = "plane", normal = { 0.2, 1, 0.1 }, offset = 0.3, friction = 0.5, restitution = 0.3 }
  local col = w:collider(def)
  rain(w, -1, 1, 1, -1, 1, 8)
  w:cloth{ origin = { -0.8, 1.5, -0.8 }, size = { 1.6, 1.6 }, res = { 16, 16 }, radius = 0.02 }
  local worst, contacts = watch(w, col, "plane", def, 150)
  expect.ge(worst, -eps, "min over frames of distance - radius")
  expect.lt(worst, 1e-9, "some particle did touch the collider")
  expect.gt(contacts, 0, "particles are touching it at the end")
end)

test("sphere: a cloth draped over it, particles raining on it", function()
  local w = wobble.world{ iterations = 2 }
  local def = { shape = "sphere", center = { 0, 0, 0 }, radius = 0.5, friction = 0.2 }
  local col = w:collider(def)
  w:cloth{ origin = { -0.7, 0.6, -0.7 }, size = { 1.4, 1.4 }, res = { 24, 24 }, radius = 0.015, bend_links = 1e-4 }
  rain(w, -0.4, 0.4, 1.0, -0.4, 0.4, 6)
  local worst, contacts = watch(w, col, "sphere", def, 120, { 0, 0, 0 })
  expect.ge(worst, -eps, "min over frames of distance - radius")
  expect.lt(worst, 1e-9, "some particle did touch the collider")
  expect.gt(contacts, 0, "the cloth rests on it")
end)

test("box: rotated 30 degrees about (1,1,0), a lattice and particles fall on it", function()
  local w = wobble.world{}
  local s = math.sin(math.pi / 12) / math.sqrt(2)
  local q = { math.cos(math.pi / 12), s, s, 0 }
  local def = { shape = "box", center = { 0, 0, 0 }, half = { 0.6, 0.3, 0.5 }, rotation = q, friction = 0.4 }
  local col = w:collider(def)
  w:lattice{ min = { -0.3, 0.8, -0.3 }, max = { 0.3, 1.2, 0.3 }, res = { 4, 3, 4 }, radius = 0.03, compliance = 1e-5 }
  rain(w, -0.8, 0.8, 1.5, -0.7, 0.7, 7)
  local worst, contacts = watch(w, col, "box", def, 150)
  expect.ge(worst, -eps, "min over frames of distance - radius")
  expect.lt(worst, 1e-9, "some particle did touch the collider")
  expect.gt(contacts, 0, "something rests on it")
end)

test("capsule: tilted, a rope draped over it and particles raining on it", function()
  local w = wobble.world{ iterations = 3 }
  local def = { shape = "capsule", a = { -0.6, 0, -0.2 }, b = { 0.6, 0.2, 0.2 }, radius = 0.25, friction = 0.3 }
  local col = w:collider(def)
  local c0 = { col:position() }
  w:rope{ from = { -0.1, 0.6, -0.8 }, to = { 0.1, 0.6, 0.8 }, segments = 30, radius = 0.02 }
  rain(w, -0.6, 0.6, 0.8, -0.3, 0.3, 6)
  local worst, contacts = watch(w, col, "capsule", def, 150, c0)
  expect.ge(worst, -eps, "min over frames of distance - radius")
  expect.lt(worst, 1e-9, "some particle did touch the collider")
  expect.gt(contacts, 0, "the rope rests on it")
end)

test("kinematic box sweeping fast through a cloud of particles (gravity 0)", function()
  -- 6 m/s through particles at rest: 0.01 m per substep against a 0.4 m thick box
  local w = wobble.world{ gravity = { 0, 0, 0 } }
  local def = { shape = "box", center = { -1.5, 0, 0 }, half = { 0.2, 0.6, 0.6 } }
  local col = w:collider(def)
  col:set_velocity(6, 0, 0)
  rain(w, -0.5, 0.5, -0.4, -0.4, 0.4, 6)
  local worst = watch(w, col, "box", def, 40)
  expect.ge(worst, -eps, "min over frames of distance - radius")
  expect.lt(worst, 1e-9, "some particle did touch the collider")
end)

test("kinematic box rotating under particles resting on it", function()
  local w = wobble.world{}
  local def = { shape = "box", center = { 0, 0, 0 }, half = { 0.8, 0.1, 0.8 }, friction = 0.5 }
  local col = w:collider(def)
  col:set_angular_velocity(0, 0, 1.5) -- tilts the top face: particles slide, get pushed
  -- (the lowest start 0.05 above the face: none made inside it, which would go out at
  -- max_depenetration over some frames)
  rain(w, -0.6, 0.6, 0.15, -0.6, 0.6, 5)
  local worst = watch(w, col, "box", def, 90)
  expect.ge(worst, -eps, "min over frames of distance - radius")
  expect.lt(worst, 1e-9, "some particle did touch the collider")
end)
