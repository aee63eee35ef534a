-- neo_bunny.lua: a Neo-Hookean bunny from a mesh. The bunny is made here, no file: a body,
-- haunches, a head, two long ears, front paws and a tail (ellipsoids and capsules) blended
-- into one smooth closed surface (a smooth minimum of their distance functions, cut flat
-- underneath) and turned into triangles by surface nets (a vertex per grid cell the
-- surface crosses, a quad per grid edge it crosses), cleaned (short edges collapsed,
-- vertices evened out and put back on the surface): one closed 2-manifold that does not
-- cross itself. tetgen fills it with tetrahedra (w:from_mesh{tets = true}); each tet is a
-- stable Neo-Hookean element (Macklin & Müller 2021) of Young's modulus E and Poisson's
-- ratio nu, no links. It drops onto the ground, its ears swing down on the landing and
-- back up, and it comes to rest upright on its flat base, keeping its volume: soft rubber
-- (E = 2e5 Pa, nu = 0.45, 1000 kg/m^3; a drag of 3/s stills the ears within 3 s).
-- Run:     build/wobble run scripts/neo_bunny.lua [--record out/bunny/]
-- Options: --set young=1e6 (stiffer: the ears barely flex; raise substeps with it),
--          --set poisson=0.3, --set young=0 (volume constraints and links instead of
--          Neo-Hookean tets: the links hold the ears stiffly), --set tets=0 (a shell of
--          links, no tets: it folds flat), --set damping=0, --set save=1 (writes bunny.obj
--          to --out)
local args = wobble.args
local young = args.young or 2e5
local tets = args.tets ~= 0

-- ---- the shape: signed distances (negative inside), blended ------------------------------
local function ellipsoid(cx, cy, cz, rx, ry, rz, tilt_z, tilt_x)
  local cz_, sz_ = math.cos(tilt_z or 0), math.sin(tilt_z or 0)
  local cx_, sx_ = math.cos(tilt_x or 0), math.sin(tilt_x or 0)
  local rmin = math.min(rx, ry, rz)
  return function(x, y, z)
    x, y, z = x - cx, y - cy, z - cz
    x, y = cz_ * x + sz_ * y, -sz_ * x + cz_ * y -- into the part's own frame
    y, z = cx_ * y + sx_ * z, -sx_ * y + cx_ * z
    -- |p/r| - 1 scaled by the smallest radius: a distance near the surface, exact for spheres
    return (math.sqrt((x / rx) ^ 2 + (y / ry) ^ 2 + (z / rz) ^ 2) - 1) * rmin
  end
end

-- an ear: a capsule from (ax, ay) to (bx, by) in the plane z = cz, of radius r, flattened
-- across (z) by flat: round-tipped, so its tip is no sharper than its thickness
local function ear(ax, ay, bx, by, cz, r, flat, splay)
  local dx, dy = bx - ax, by - ay
  local len2 = dx * dx + dy * dy
  return function(x, y, z)
    x, y, z = x - ax, y - ay, z - cz
    local t = math.max(0, math.min(1, (x * dx + y * dy) / len2))
    local zz = (z - splay * t * math.sqrt(len2)) / flat -- leaning out as it rises
    return (math.sqrt((x - t * dx) ^ 2 + (y - t * dy) ^ 2 + zz * zz) - r) * flat
  end
end

local parts = {
  ellipsoid(0.00, 0.17, 0.00, 0.20, 0.15, 0.15),             -- body
  ellipsoid(-0.08, 0.14, 0.00, 0.14, 0.13, 0.16),            -- haunches
  ellipsoid(0.17, 0.33, 0.00, 0.11, 0.095, 0.09),            -- head
  ellipsoid(0.25, 0.31, 0.00, 0.05, 0.045, 0.05),            -- muzzle
  ear(0.15, 0.38, 0.09, 0.58, 0.045, 0.04, 0.75, 0.3),       -- ears, leaning back and apart
  ear(0.15, 0.38, 0.09, 0.58, -0.045, 0.04, 0.75, -0.3),
  ellipsoid(0.16, 0.07, 0.055, 0.07, 0.045, 0.04),            -- front paws
  ellipsoid(0.16, 0.07, -0.055, 0.07, 0.045, 0.04),
  ellipsoid(-0.22, 0.21, 0.00, 0.05, 0.05, 0.05),             -- tail
}
local BLEND, BASE = 0.03, 0.03 -- smooth-minimum radius (m); the flat base's height

local function field(x, y, z)
  local d = parts[1](x, y, z)
  for i = 2, #parts do -- polynomial smooth minimum: seams rounded over BLEND
    local e = parts[i](x, y, z)
    local h = math.max(BLEND - math.abs(d - e), 0) / BLEND
    d = math.min(d, e) - h * h * BLEND / 4
  end
  return math.max(d, BASE - y) -- cut flat underneath: it sits on its base
end

-- ---- surface nets ------------------------------------------------------------------------
local H = args.spacing or 0.02 -- grid spacing (m): the surface's edge length
local X0, Y0, Z0 = -0.34, BASE - 2 * H, -0.22
local NX, NY, NZ = math.ceil(0.72 / H), math.ceil((0.68 - Y0) / H), math.ceil(0.44 / H)
local val = {}
local function gi(i, j, k) return (k * (NY + 1) + j) * (NX + 1) + i + 1 end
for k = 0, NZ do
  for j = 0, NY do
    for i = 0, NX do
      local f = field(X0 + i * H, Y0 + j * H, Z0 + k * H)
      if f == 0 then f = 1e-12 end -- no grid point on the surface: every crossing is strict
      if i == 0 or j == 0 or k == 0 or i == NX or j == NY or k == NZ then assert(f > 0, "the grid holds the bunny") end
      val[gi(i, j, k)] = f
    end
  end
end

-- A grid face whose corners alternate in sign (a saddle finer than the grid, where two parts
-- meet) would put four quads on one edge: the corner nearest the surface moves across it
-- (by under a cell), until no face is ambiguous
local function ambiguous(a, b, c, d) -- corners in order around the face
  local sa, sb, sc, sd = val[a] < 0, val[b] < 0, val[c] < 0, val[d] < 0
  return sa == sc and sb == sd and sa ~= sb
end
local FACES = { { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 } }, { { 0, 0, 0 }, { 0, 1, 0 }, { 0, 1, 1 }, { 0, 0, 1 } },
                { { 0, 0, 0 }, { 0, 0, 1 }, { 1, 0, 1 }, { 1, 0, 0 } } }
for _ = 1, 20 do
  local changed = 0
  for k = 0, NZ - 1 do
    for j = 0, NY - 1 do
      for i = 0, NX - 1 do
        for _, face in ipairs(FACES) do
          local c = {}
          for q = 1, 4 do c[q] = gi(i + face[q][1], j + face[q][2], k + face[q][3]) end
          if ambiguous(c[1], c[2], c[3], c[4]) then
            local best = c[1]
            for q = 2, 4 do if math.abs(val[c[q]]) < math.abs(val[best]) then best = c[q] end end
            val[best] = -val[best]
            changed = changed + 1
          end
        end
      end
    end
  end
  if changed == 0 then break end
end

-- a vertex per crossed cell: the mean of its edges' crossings
local CORNER = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 1, 1, 0 }, { 0, 0, 1 }, { 1, 0, 1 }, { 0, 1, 1 }, { 1, 1, 1 } }
local EDGES = { { 1, 2 }, { 3, 4 }, { 5, 6 }, { 7, 8 }, { 1, 3 }, { 2, 4 }, { 5, 7 }, { 6, 8 }, { 1, 5 }, { 2, 6 }, { 3, 7 }, { 4, 8 } }
local verts, cell_vertex = {}, {}
local function ci(i, j, k) return (k * NY + j) * NX + i + 1 end
for k = 0, NZ - 1 do
  for j = 0, NY - 1 do
    for i = 0, NX - 1 do
      local f = {}
      for c = 1, 8 do f[c] = val[gi(i + CORNER[c][1], j + CORNER[c][2], k + CORNER[c][3])] end
      local sx, sy, sz, n = 0, 0, 0, 0
      for _, e in ipairs(EDGES) do
        local a, b = f[e[1]], f[e[2]]
        if (a < 0) ~= (b < 0) then
          local t = a / (a - b)
          local ca, cb = CORNER[e[1]], CORNER[e[2]]
          sx = sx + ca[1] + t * (cb[1] - ca[1])
          sy = sy + ca[2] + t * (cb[2] - ca[2])
          sz = sz + ca[3] + t * (cb[3] - ca[3])
          n = n + 1
        end
      end
      if n > 0 then
        verts[#verts + 1] = { X0 + (i + sx / n) * H, Y0 + (j + sy / n) * H, Z0 + (k + sz / n) * H }
        cell_vertex[ci(i, j, k)] = #verts
      end
    end
  end
end

-- a quad per crossed grid edge, between the four cells around it, facing out (toward > 0)
local tris = {}
local function dist2(a, b) return (a[1] - b[1]) ^ 2 + (a[2] - b[2]) ^ 2 + (a[3] - b[3]) ^ 2 end
local function quad(a, b, c, d, flip)
  if flip then a, b, c, d = a, d, c, b end
  -- split along the shorter diagonal: better-shaped triangles
  if dist2(verts[a], verts[c]) <= dist2(verts[b], verts[d]) then
    tris[#tris + 1] = { a, b, c }
    tris[#tris + 1] = { a, c, d }
  else
    tris[#tris + 1] = { a, b, d }
    tris[#tris + 1] = { b, c, d }
  end
end
for k = 1, NZ - 1 do
  for j = 1, NY - 1 do
    for i = 1, NX - 1 do
      local f0 = val[gi(i, j, k)] < 0
      -- the edge along x from (i,j,k): cells (i, j-1..j, k-1..k), counter-clockwise about +x
      if f0 ~= (val[gi(i + 1, j, k)] < 0) then
        quad(cell_vertex[ci(i, j - 1, k - 1)], cell_vertex[ci(i, j, k - 1)], cell_vertex[ci(i, j, k)],
             cell_vertex[ci(i, j - 1, k)], not f0)
      end
      if f0 ~= (val[gi(i, j + 1, k)] < 0) then -- along y: about +y, (z, x) order
        quad(cell_vertex[ci(i - 1, j, k - 1)], cell_vertex[ci(i - 1, j, k)], cell_vertex[ci(i, j, k)],
             cell_vertex[ci(i, j, k - 1)], not f0)
      end
      if f0 ~= (val[gi(i, j, k + 1)] < 0) then -- along z: about +z, (x, y) order
        quad(cell_vertex[ci(i - 1, j - 1, k)], cell_vertex[ci(i, j - 1, k)], cell_vertex[ci(i, j, k)],
             cell_vertex[ci(i - 1, j, k)], not f0)
      end
    end
  end
end

-- Surface nets leave some vertices close together (crossings near a cell's face), and
-- tetgen keeps the surface: its tiny triangles would make tiny tets (and the substep must
-- stay below a wave's time across the smallest). Edges under a third of the spacing are
-- collapsed to their midpoints where that keeps the surface a 2-manifold (the two ends
-- share exactly two neighbours) and turns no triangle over; then a few rounds of moving
-- each vertex halfway to its neighbours' mean, and back onto the surface (Newton steps
-- along the field's gradient), even out the triangles without changing the shape.
local function cross(a, b, c)
  local ux, uy, uz = b[1] - a[1], b[2] - a[2], b[3] - a[3]
  local vx, vy, vz = c[1] - a[1], c[2] - a[2], c[3] - a[3]
  return uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
end
for _ = 1, 10 do
  local nb, around = {}, {}
  for v = 1, #verts do nb[v], around[v] = {}, {} end
  for t, tri in ipairs(tris) do
    for e = 1, 3 do
      local a, b = tri[e], tri[e % 3 + 1]
      nb[a][b], nb[b][a] = true, true
      around[a][#around[a] + 1] = t
    end
  end
  local touched, dead, collapsed = {}, {}, 0
  for _, tri in ipairs(tris) do
    for e = 1, 3 do
      local a, b = tri[e], tri[e % 3 + 1]
      if not touched[a] and not touched[b] and dist2(verts[a], verts[b]) < (H / 3) ^ 2 then
        local common = 0
        for q in pairs(nb[a]) do if nb[b][q] then common = common + 1 end end
        local mid = { (verts[a][1] + verts[b][1]) / 2, (verts[a][2] + verts[b][2]) / 2, (verts[a][3] + verts[b][3]) / 2 }
        local ok = common == 2
        for _, v in ipairs(ok and { a, b } or {}) do -- no triangle that stays may turn over
          for _, t in ipairs(around[v]) do
            local r = tris[t]
            local has_a, has_b = r[1] == a or r[2] == a or r[3] == a, r[1] == b or r[2] == b or r[3] == b
            if not (has_a and has_b) then
              local p = { verts[r[1]], verts[r[2]], verts[r[3]] }
              local nx, ny, nz = cross(p[1], p[2], p[3])
              for k = 1, 3 do if r[k] == v then p[k] = mid end end
              local mx, my, mz = cross(p[1], p[2], p[3])
              if nx * mx + ny * my + nz * mz <= 0 then ok = false end
            end
          end
        end
        if ok then
          verts[a] = mid
          for _, t in ipairs(around[b]) do
            local r = tris[t]
            if r[1] == a or r[2] == a or r[3] == a then dead[t] = true
            else for k = 1, 3 do if r[k] == b then r[k] = a end end end
          end
          for q in pairs(nb[a]) do touched[q] = true end
          for q in pairs(nb[b]) do touched[q] = true end
          collapsed = collapsed + 1
        end
      end
    end
  end
  if collapsed == 0 then break end
  -- drop the dead triangles and the vertices no triangle uses, renumbering
  local used, kept = {}, {}
  for t, tri in ipairs(tris) do
    if not dead[t] then kept[#kept + 1] = tri; for k = 1, 3 do used[tri[k]] = true end end
  end
  local new_id, new_verts = {}, {}
  for v = 1, #verts do
    if used[v] then new_verts[#new_verts + 1] = verts[v]; new_id[v] = #new_verts end
  end
  for _, tri in ipairs(kept) do for k = 1, 3 do tri[k] = new_id[tri[k]] end end
  verts, tris = new_verts, kept
end

local nbr = {}
for v = 1, #verts do nbr[v] = {} end
for _, t in ipairs(tris) do
  for e = 1, 3 do
    local a, b = t[e], t[e % 3 + 1]
    nbr[a][b], nbr[b][a] = true, true
  end
end
local function project(p)
  for _ = 1, 3 do
    local f, e = field(p[1], p[2], p[3]), 1e-5
    local gx = (field(p[1] + e, p[2], p[3]) - f) / e
    local gy = (field(p[1], p[2] + e, p[3]) - f) / e
    local gz = (field(p[1], p[2], p[3] + e) - f) / e
    local g2 = gx * gx + gy * gy + gz * gz
    if g2 > 0 then p[1], p[2], p[3] = p[1] - f * gx / g2, p[2] - f * gy / g2, p[3] - f * gz / g2 end
  end
end
for _ = 1, args.smooth or 6 do
  local moved = {}
  for v, p in ipairs(verts) do
    local sx, sy, sz, n = 0, 0, 0, 0
    for q in pairs(nbr[v]) do
      sx, sy, sz, n = sx + verts[q][1], sy + verts[q][2], sz + verts[q][3], n + 1
    end
    moved[v] = { (p[1] + sx / n) / 2, (p[2] + sy / n) / 2, (p[3] + sz / n) / 2 }
    project(moved[v])
  end
  verts = moved
end

local m = wobble.mesh{ vertices = verts, triangles = tris }
local x0, y0, z0, x1, y1, z1 = m:bounds()
local mesh_volume = 0 -- the divergence theorem over the outward triangles
for _, t in ipairs(tris) do
  local a, b, c = verts[t[1]], verts[t[2]], verts[t[3]]
  mesh_volume = mesh_volume + (a[1] * (b[2] * c[3] - b[3] * c[2]) - a[2] * (b[1] * c[3] - b[3] * c[1])
                               + a[3] * (b[1] * c[2] - b[2] * c[1])) / 6
end
if args.save == 1 then m:save_obj("bunny.obj") end

-- ---- the scene -----------------------------------------------------------------------------
local DROP = 0.25 -- its base this high above the ground
m:transform{ translate = { -(x0 + x1) / 2, DROP - y0, -(z0 + z1) / 2 } }
-- a drag of 3/s (world damping) stills the ears' swinging within the run
local w = wobble.world{ substeps = args.substeps or 40, iterations = 1, damping = args.damping or 3 }
w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = 0, friction = 0.8 }
local DENSITY = 1000
local bunny
if tets then
  bunny = w:from_mesh(m, { tets = true, max_volume = args.max_volume or 2e-5, quality = args.quality, mass = DENSITY * mesh_volume,
                           young = young > 0 and young or nil, poisson = young > 0 and (args.poisson or 0.45) or nil,
                           radius = 0.004 })
else
  bunny = w:from_mesh(m, { mass = DENSITY * mesh_volume, radius = 0.004 })
end
local h0 = y1 - y0

-- the ear tips: the topmost surface vertex of each ear (z > 0 and z < 0); the head's middle
local tip, tipy = {}, { -math.huge, -math.huge }
local head, headd, core, cored = nil, math.huge, nil, math.huge
for i = 1, m:vertex_count() do
  local x, y, z = w:position(bunny.first + i - 1)
  local s = z > 0 and 1 or 2
  if y > tipy[s] then tip[s], tipy[s] = bunny.first + i - 1, y end
end
for _, p in ipairs(bunny.particles) do -- the particle nearest the head's centre (interior, with tets)
  local x, y, z = w:position(p)
  local d = (x - (0.17 - (x0 + x1) / 2)) ^ 2 + (y - (0.33 - y0 + DROP)) ^ 2 + z ^ 2
  if d < headd then head, headd = p, d end
  d = (x - (0 - (x0 + x1) / 2)) ^ 2 + (y - (0.17 - y0 + DROP)) ^ 2 + z ^ 2 -- the body's centre
  if d < cored then core, cored = p, d end
end
local function axis() -- body centre to head centre, unit
  local ax, ay, az = w:position(core)
  local bx, by, bz = w:position(head)
  local l = math.sqrt((bx - ax) ^ 2 + (by - ay) ^ 2 + (bz - az) ^ 2)
  return (bx - ax) / l, (by - ay) / l, (bz - az) / l
end
local axis0 = { axis() }
-- an ear's height above the head's centre: it drops when the ear bends on the landing
local function ear_rise()
  local _, hy = w:position(head)
  local _, ya = w:position(tip[1])
  local _, yb = w:position(tip[2])
  return (ya + yb) / 2 - hy
end
local rise0 = ear_rise()

local function volume()
  local v = 0
  for i = 1, w:tet_count() do
    local det, _, v0 = w:tet_info(i)
    v = v + det * v0
  end
  return v
end

local lowest_rise, landed_at, min_vol, max_vol = math.huge, nil, math.huge, 0
local late_lo, late_hi = math.huge, -math.huge
local v_rest = tets and young > 0 and volume() or 0
w:run{ seconds = args.seconds or 3, on_frame = function(w, f, t)
  local _, miny = w:bounds()
  if miny < 0.02 then
    landed_at = landed_at or t
    lowest_rise = math.min(lowest_rise, ear_rise())
  end
  if t > (args.seconds or 3) - 0.5 then -- the last half second: settled?
    local r = ear_rise()
    late_lo, late_hi = math.min(late_lo, r), math.max(late_hi, r)
  end
  if v_rest > 0 then
    local v = volume()
    min_vol, max_vol = math.min(min_vol, v), math.max(max_vol, v)
  end
end }

local inverted = 0
for i = 1, w:tet_count() do
  if w:tet_info(i) <= 0 then inverted = inverted + 1 end
end
local minx, miny, minz, maxx, maxy, maxz = w:bounds()
-- upright: its body-to-head axis turned by how much since it was dropped
local ux, uy, uz = axis()
local lean = math.deg(math.acos(math.min(1, ux * axis0[1] + uy * axis0[2] + uz * axis0[3])))
print(string.format("neo bunny: %d surface vertices, %d triangles, %.4f m^3; %d particles, %d tets; %.2f m tall",
                    #verts, #tris, mesh_volume, bunny.count, bunny.tet_count or 0, h0))
print(string.format("  ears %.3f m above the head's centre, %.3f m on the landing, %.3f m at the end; "
                    .. "rests %.3f m tall, base at %.4f m, turned %.1f deg; volume %.2f%%..%.2f%% of rest; "
                    .. "%d inverted tets", rise0, lowest_rise, ear_rise(), maxy - miny, miny, lean,
                    v_rest > 0 and 100 * min_vol / v_rest or 0, v_rest > 0 and 100 * max_vol / v_rest or 0, inverted))

if test then -- under `wobble test`: the header's claims
  test("the bunny mesh is a closed surface that tetgen fills with Neo-Hookean tets alone", function()
    expect.gt(mesh_volume, 0.02, "a solid of the bunny's size, triangles facing out")
    expect.gt(bunny.tet_count or 0, 1000, "filled with tets")
    expect.eq(bunny.constraint_count, 0, "no links: the tets alone hold it")
  end)
  test("its ears flex on the landing and spring back", function()
    expect.truthy(landed_at, "it lands")
    -- the soft ears swing down by many centimetres. In free fall they have their rest
    -- shape; on the ground they sag under their weight: leaning back ~17 deg, each is a
    -- cantilever (L ~ 0.25 m, elliptic section 0.08 x 0.06 m) under sin 17 deg of its
    -- weight, bent by q L^4 / (8 E I) ~ 11 N/m * 3.9e-3 m^4 / (8 * 2e5 Pa * 1.5e-6 m^4)
    -- ~ 2 cm, mostly sideways: its tip drops by ~ 2 cm * sin 17 deg ~ 5 mm
    expect.lt(lowest_rise, rise0 - 0.05, "the ears swing down by over 5 cm on the landing")
    expect.near(ear_rise(), rise0 - 0.005, 0.008, "and come back up, sagging ~5 mm under their weight")
    expect.lt(late_hi - late_lo, 0.005, "and have stopped swinging (the last half second)")
  end)
  test("it comes to rest upright on its base with its volume and no inverted tet", function()
    expect.lt(miny, 0.01, "on the ground (particle radius 4 mm)")
    expect.gt(miny, -0.002, "not inside it")
    -- its own weight squashes soft rubber by ~ rho g h / E = 1000 * 9.81 * 0.5 / 5e4 ~ 10 %
    -- at the base, a few % over its height
    expect.near((maxy - miny) / h0, 1, 0.05, "its height, sagging a little under its weight")
    expect.lt(lean, 5, "upright: turned by under 5 degrees, not toppled")
    -- nu = 0.45: the bulk modulus is 10x the shear one, so the impact's pressure
    -- (rho v^2 ~ 2.5 kPa at 2.2 m/s against K ~ 170 kPa) changes its volume by under 2 %
    expect.gt(min_vol / v_rest, 0.97, "volume kept within 3 % on the landing")
    expect.lt(max_vol / v_rest, 1.03, "and not inflated")
    expect.eq(inverted, 0, "no tet left inverted")
  end)
end
