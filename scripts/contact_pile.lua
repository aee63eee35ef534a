-- contact_pile.lua: twelve soft balls dropped into a box pile up instead of merging
-- (particle-particle contacts). Each ball is a hollow icosphere (42 particles,
-- built here with wobble.mesh, subdivided once) turned into a body by w:from_mesh, with
-- links to each particle's nearest neighbours across the inside so the shell keeps its
-- shape; every ball is a contact group of its own, so balls push each other while a
-- ball's own particles do not. The box is a floor plane and four box colliders. Try --set contacts=0 to
-- watch the balls fall into one another and merge in a heap on the floor.
-- Run: build/wobble run scripts/contact_pile.lua [--record out/pile/] (seen from above,
--   into the box)
local args = wobble.args
local w = wobble.world{ substeps = 20, iterations = 2, contacts = args.contacts ~= 0 }
-- the box's inner half-width and its walls' height (m): the walls stand higher than the
-- third ball up (~0.45 m), which otherwise can roll out over them (1 mm moved in a ball's
-- drop point decides it)
local half, wall = 0.45, 0.5
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
-- four walls, thin boxes whose inner faces are at |x|, |z| = half
local t = 0.02
for _, c in ipairs{ { half + t, 0, 0, t, wall / 2, half + 2 * t }, { -half - t, 0, 0, t, wall / 2, half + 2 * t },
                    { 0, 0, half + t, half, wall / 2, t }, { 0, 0, -half - t, half, wall / 2, t } } do
  w:collider{ shape = "box", center = { c[1], wall / 2, c[3] }, half = { c[4], c[5], c[6] }, friction = 0.2 }
end

-- an icosahedron with every triangle split in four, pushed onto the sphere of radius R
local function icosphere(R)
  local t = (1 + math.sqrt(5)) / 2
  local v = { {-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1} }
  local f = { {1,12,6}, {1,6,2}, {1,2,8}, {1,8,11}, {1,11,12}, {2,6,10}, {6,12,5}, {12,11,3},
              {11,8,7}, {8,2,9}, {4,10,5}, {4,5,3}, {4,3,7}, {4,7,9}, {4,9,10}, {5,10,6},
              {3,5,12}, {7,3,11}, {9,7,8}, {10,9,2} }
  local mid = {}
  local function midpoint(a, b)
    local key = math.min(a, b) .. ":" .. math.max(a, b)
    if not mid[key] then
      v[#v + 1] = { (v[a][1] + v[b][1]) / 2, (v[a][2] + v[b][2]) / 2, (v[a][3] + v[b][3]) / 2 }
      mid[key] = #v
    end
    return mid[key]
  end
  local tris = {}
  for _, tri in ipairs(f) do
    local a, b, c = tri[1], tri[2], tri[3]
    local ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
    for _, s in ipairs{ {a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca} } do tris[#tris + 1] = s end
  end
  for i, p in ipairs(v) do
    local l = math.sqrt(p[1] ^ 2 + p[2] ^ 2 + p[3] ^ 2)
    v[i] = { R * p[1] / l, R * p[2] / l, R * p[3] / l }
  end
  return wobble.mesh{ vertices = v, triangles = tris }
end

local R = 0.11
local balls = {}
-- nine balls over a 3 x 3 grid, then three more dropped onto them from higher up
local drops = {}
for i = -1, 1 do
  for j = -1, 1 do drops[#drops + 1] = { 0.27 * i + 0.01 * j, 0.25 + 0.05 * (i + 2 * j + 3), 0.27 * j } end
end
for _, d in ipairs{ { -0.12, 0.8, -0.1 }, { 0.13, 1.0, 0.02 }, { -0.02, 1.2, 0.14 } } do drops[#drops + 1] = d end
for _, d in ipairs(drops) do
  local m = icosphere(R)
  m:transform{ translate = d }
  balls[#balls + 1] = w:from_mesh(m, { mass = 0.2, neighbours = 6, compliance = 1e-5, damping = 0.05,
                                       friction = 0.4 })
  m:close()
end

-- the camera `--record` draws with and `wobble view` starts with
wobble.camera{ eye = {0.5, 2.4, 0.8}, target = {0, 0.1, 0} }
w:run{ seconds = args.seconds or 5 }

-- the deepest overlap between particles of different balls, as a fraction of the
-- contact distance r_i + r_j (every pair: 12 x 11 / 2 x 42^2, quick enough)
local function worst_overlap()
  local worst = 0
  for i = 1, #balls do
    for j = i + 1, #balls do
      for _, p in ipairs(balls[i].particles) do
        local px, py, pz = w:position(p)
        local rp = w:radius(p)
        for _, q in ipairs(balls[j].particles) do
          local qx, qy, qz = w:position(q)
          local d = math.sqrt((px - qx) ^ 2 + (py - qy) ^ 2 + (pz - qz) ^ 2)
          local rr = rp + w:radius(q)
          worst = math.max(worst, (rr - d) / rr)
        end
      end
    end
  end
  return worst
end
local function fastest()
  local speed = 0
  for _, b in ipairs(balls) do
    for _, p in ipairs(b.particles) do
      local vx, vy, vz = w:velocity(p)
      speed = math.max(speed, math.sqrt(vx * vx + vy * vy + vz * vz))
    end
  end
  return speed
end
-- every ball's centre (the mean of its particles) inside the box, and the highest one
-- resting on others (a second layer: without contacts they all end on the floor)
local worst_centre, highest = -math.huge, 0
for i, b in ipairs(balls) do
  local sx, sy, sz = 0, 0, 0
  for _, p in ipairs(b.particles) do
    local x, y, z = w:position(p)
    sx, sy, sz = sx + x, sy + y, sz + z
  end
  local n = #b.particles
  sx, sy, sz = sx / n, sy / n, sz / n
  worst_centre = math.max(worst_centre, math.abs(sx) - half, math.abs(sz) - half, -sy)
  highest = math.max(highest, sy)
  print(string.format("ball %2d: centre (%.3f, %.3f, %.3f)", i, sx, sy, sz))
end
local overlap = worst_overlap()
local speed = fastest()
print(string.format("deepest overlap between balls: %.1f%% of the contact distance; " ..
                    "a ball's centre farthest outside the box: %.3f m; fastest particle: %.3f m/s; %d contacts",
                    100 * overlap, worst_centre, speed, w:stats().particle_contacts))

if test then  -- under `wobble test`: the header's claim
  test("the balls pile up in the box without merging", function()
    expect.lt(overlap, 0.25, "no two balls' particles closer than 3/4 of their contact distance")
    expect.lt(worst_centre, -0.5 * R, "every ball's centre inside the box, half a radius from the walls")
    expect.gt(highest, 2 * R, "some ball rests on others")
    expect.lt(speed, 0.2, "the pile is at rest")
  end)
end
