-- make_assets.lua: makes every file in assets/ (no third-party art). Run from the
-- repository's root:
--
--   build/wobble run assets/make_assets.lua --out assets
--
--   rounded_cube.obj  a high-poly rounded cube, 1 m across (Wavefront OBJ)
--   cube.obj          the coarsest closed mesh: a cube 1 m across, 8 corners, 12 triangles
--                     wound outwards (Wavefront OBJ)
--   torus.ply         a high-poly torus, 1 m across (Stanford PLY)
--   logo.json         the "WOBBLE" logo as six soft letters on a ground plane: a particle
--                     config (format wobble-particles, version 1), one part per letter
--
-- The output is deterministic: the same generator gives the same bytes.

-- ---- rounded cube ----------------------------------------------------------------------------
-- Each face is an n x n grid. A point p on the cube [-1,1]^3 moves to q + r (p - q)/|p - q|
-- with q = p clamped to the inner box [-b, b]^3 (b = 1 - r): flat faces, rounded edges and
-- corners. The grid is spaced evenly along the rounded profile (flat part, then a quarter
-- arc shared with the next face), so the rounding gets as many vertices as the flat part.
local function rounded_cube(n, r)
  local b = 1 - r
  local half = b + r * math.pi / 4 -- half the profile length of one face
  local function coord(s) -- s in [-1, 1] -> cube coordinate; odd in s, so faces meet exactly
    local d = math.abs(s) * half
    local u = d <= b and d or b + r * math.tan((d - b) / r)
    return s < 0 and -u or u
  end
  local verts, tris = {}, {}
  for axis = 1, 3 do
    for _, side in ipairs{ -1, 1 } do
      local u, w = axis % 3 + 1, (axis + 1) % 3 + 1 -- (axis, u, w) right-handed
      local base = #verts
      for j = 0, n do
        for i = 0, n do
          local p = {}
          p[axis], p[u], p[w] = side, coord(2 * i / n - 1), coord(2 * j / n - 1)
          local q, d = {}, {}
          for k = 1, 3 do
            q[k] = math.max(-b, math.min(b, p[k]))
            d[k] = p[k] - q[k]
          end
          local l = math.sqrt(d[1] ^ 2 + d[2] ^ 2 + d[3] ^ 2)
          local v = {}
          for k = 1, 3 do v[k] = 0.5 * (l > 0 and q[k] + r * d[k] / l or p[k]) end
          verts[#verts + 1] = v
        end
      end
      for j = 0, n - 1 do
        for i = 0, n - 1 do
          local a = base + j * (n + 1) + i + 1
          local c, e, f = a + 1, a + n + 1, a + n + 2
          if side > 0 then
            tris[#tris + 1] = { a, c, f }; tris[#tris + 1] = { a, f, e }
          else
            tris[#tris + 1] = { a, f, c }; tris[#tris + 1] = { a, e, f }
          end
        end
      end
    end
  end
  -- the faces' border rows are the same points: weld them (order of first use kept)
  return wobble.mesh{ vertices = verts, triangles = tris, weld = 1e-9 }
end

-- ---- torus --------------------------------------------------------------------------------------
local function torus(R, r, nu, nv)
  local verts, tris = {}, {}
  for j = 0, nv - 1 do
    local phi = 2 * math.pi * j / nv
    for i = 0, nu - 1 do
      local th = 2 * math.pi * i / nu
      local rho = R + r * math.cos(phi)
      verts[#verts + 1] = { rho * math.cos(th), r * math.sin(phi), rho * math.sin(th) }
    end
  end
  local function id(i, j) return (j % nv) * nu + (i % nu) + 1 end
  for j = 0, nv - 1 do
    for i = 0, nu - 1 do
      tris[#tris + 1] = { id(i, j), id(i, j + 1), id(i + 1, j) }
      tris[#tris + 1] = { id(i + 1, j), id(i, j + 1), id(i + 1, j + 1) }
    end
  end
  return wobble.mesh{ vertices = verts, triangles = tris }
end

-- ---- the logo: letters of voxels ------------------------------------------------------------------
-- voxels that touch only along an edge would be a hinge: every voxel shares a face with
-- the rest of its letter
local FONT = {
  W = { "X...X", "X...X", "X.X.X", "X.X.X", "XXXXX" },
  O = { "XXXX", "X..X", "X..X", "X..X", "XXXX" },
  B = { "XXX.", "X..X", "XXXX", "X..X", "XXX." },
  L = { "X..", "X..", "X..", "X..", "XXX" },
  E = { "XXX", "X..", "XX.", "X..", "XXX" },
}
local PIXEL, LAYERS, GAP = 0.08, 2, 0.08 -- voxel size, voxels deep, gap between letters (m)

local function fmt(x)
  local s = string.format("%.6f", x):gsub("0+$", ""):gsub("%.$", "")
  return s == "-0" and "0" or s
end

-- every letter: particles at its voxels' corners (shared), a link between every two corners
-- of a voxel, and the hull's outer faces as a surface
local function logo(word)
  local particles, constraints, surfaces, parts = {}, {}, {}, {}
  local x0 = 0
  for c in word:gmatch(".") do
    local rows = FONT[c]
    local w, h = #rows[1], #rows
    local first = #particles
    local index = {} -- "i,j,k" -> 0-based particle id
    local function corner(i, j, k)
      local key = i .. "," .. j .. "," .. k
      if not index[key] then
        index[key] = #particles
        particles[#particles + 1] = { x0 + i * PIXEL, (h - j) * PIXEL, (k - LAYERS / 2) * PIXEL }
      end
      return index[key]
    end
    local filled = function(i, j) return j >= 1 and j <= h and i >= 1 and i <= w and rows[j]:sub(i, i) == "X" end
    local links, seen, tris = {}, {}, {}
    local function quad(a, b2, c2, d)
      tris[#tris + 1] = { a, b2, c2 }
      tris[#tris + 1] = { a, c2, d }
    end
    -- rows top to bottom: pixel (i, j) spans x in [i-1, i], y in [h-j, h-j+1] (pixel units);
    -- LAYERS voxels deep along z
    for j = 1, h do
      for i = 1, w do
        for layer = 0, LAYERS - 1 do
        if filled(i, j) then
          local id = {}
          for dk = 0, 1 do
            for dj = 0, 1 do
              for di = 0, 1 do id[#id + 1] = corner(i - 1 + di, j - 1 + dj, layer + dk) end
            end
          end
          for a = 1, 8 do
            for b2 = a + 1, 8 do
              local p, q = math.min(id[a], id[b2]), math.max(id[a], id[b2])
              local key = p .. "," .. q
              if not seen[key] then
                seen[key] = true
                links[#links + 1] = { p, q }
              end
            end
          end
          -- corners: id[1 + di + 2 dj + 4 dk]; y grows with -j, so dj = 1 is the lower side
          local function C(di, dj, dk) return id[1 + di + 2 * dj + 4 * dk] end
          if layer == 0 then quad(C(0, 0, 0), C(1, 0, 0), C(1, 1, 0), C(0, 1, 0)) end          -- front (z-)
          if layer == LAYERS - 1 then quad(C(0, 0, 1), C(0, 1, 1), C(1, 1, 1), C(1, 0, 1)) end -- back (z+)
          if not filled(i - 1, j) then quad(C(0, 0, 0), C(0, 1, 0), C(0, 1, 1), C(0, 0, 1)) end
          if not filled(i + 1, j) then quad(C(1, 0, 0), C(1, 0, 1), C(1, 1, 1), C(1, 1, 0)) end
          if not filled(i, j - 1) then quad(C(0, 0, 0), C(0, 0, 1), C(1, 0, 1), C(1, 0, 0)) end
          if not filled(i, j + 1) then quad(C(0, 1, 0), C(1, 1, 0), C(1, 1, 1), C(0, 1, 1)) end
        end
        end
      end
    end
    for _, l in ipairs(links) do constraints[#constraints + 1] = l end
    surfaces[#surfaces + 1] = tris
    parts[#parts + 1] = { name = c .. #parts + 1, first = first, count = #particles - first }
    x0 = x0 + w * PIXEL + GAP
  end
  -- centre the word on x = 0
  for _, p in ipairs(particles) do p[1] = p[1] - (x0 - GAP) / 2 end
  local out = {
    "{\n",
    '  "format": "wobble-particles",\n',
    '  "version": 1,\n',
    string.format('  "description": "the %s logo: %d soft letters of voxels, %d mm each, on a ground plane '
                  .. '(made by assets/make_assets.lua)",\n', word, #word, math.floor(PIXEL * 1000 + 0.5)),
    string.format('  "defaults": {"mass": 0.01, "radius": 0.01, "compliance": %s, "damping": %s},\n',
                  wobble.args.compliance or "0.001", wobble.args.damping or "0.02"),
    '  "colliders": [\n    {"shape": "plane", "normal": [0, 1, 0], "offset": 0, "friction": 0.6}\n  ],\n',
    '  "parts": [\n',
  }
  for i, p in ipairs(parts) do
    out[#out + 1] = string.format('    {"name": "%s", "first": %d, "count": %d}%s\n', p.name, p.first, p.count,
                                  i < #parts and "," or "")
  end
  out[#out + 1] = '  ],\n  "particles": [\n'
  for i, p in ipairs(particles) do
    out[#out + 1] = string.format('    {"position": [%s, %s, %s]}%s\n', fmt(p[1]), fmt(p[2] + 0.011), fmt(p[3]),
                                  i < #particles and "," or "")
  end
  out[#out + 1] = '  ],\n  "constraints": [\n'
  for i, l in ipairs(constraints) do
    out[#out + 1] = string.format('    {"type": "distance", "particles": [%d, %d]}%s\n', l[1], l[2],
                                  i < #constraints and "," or "")
  end
  out[#out + 1] = '  ],\n  "surfaces": [\n'
  for s, tris in ipairs(surfaces) do
    local ids = {}
    for _, t in ipairs(tris) do ids[#ids + 1] = string.format("%d, %d, %d", t[1], t[2], t[3]) end
    out[#out + 1] = '    {"triangles": [' .. table.concat(ids, ", ") .. "]}" .. (s < #surfaces and ",\n" or "\n")
  end
  out[#out + 1] = "  ]\n}\n"
  return table.concat(out), #particles, #constraints
end

-- ---- write them ---------------------------------------------------------------------------------------
local cube = rounded_cube(32, 0.2)
assert(cube:save_obj("rounded_cube.obj"))
print(string.format("rounded_cube.obj: %d vertices, %d triangles", cube:vertex_count(), cube:triangle_count()))

local box = wobble.mesh{
  vertices = { { -0.5, -0.5, -0.5 }, { 0.5, -0.5, -0.5 }, { 0.5, 0.5, -0.5 }, { -0.5, 0.5, -0.5 },
               { -0.5, -0.5, 0.5 }, { 0.5, -0.5, 0.5 }, { 0.5, 0.5, 0.5 }, { -0.5, 0.5, 0.5 } },
  triangles = { { 1, 3, 2 }, { 1, 4, 3 }, { 5, 6, 7 }, { 5, 7, 8 }, { 1, 2, 6 }, { 1, 6, 5 },
                { 2, 3, 7 }, { 2, 7, 6 }, { 3, 4, 8 }, { 3, 8, 7 }, { 4, 1, 5 }, { 4, 5, 8 } } }
assert(box:save_obj("cube.obj"))
print(string.format("cube.obj: %d vertices, %d triangles", box:vertex_count(), box:triangle_count()))

local ring = torus(0.35, 0.15, 128, 48)
assert(ring:save("torus.ply"))
print(string.format("torus.ply: %d vertices, %d triangles", ring:vertex_count(), ring:triangle_count()))

local json, np, nc = logo("WOBBLE")
local f = assert(io.open("logo.json", "w"))
f:write(json)
f:close()
print(string.format("logo.json: %d particles, %d constraints, 6 parts", np, nc))
