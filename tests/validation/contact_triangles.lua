-- contact_triangles.lua: particle-triangle contacts against physics.
--
-- The model (src/core/tricontact.c): every substep a particle closer than its radius r
-- to a triangle of a registered surface (a cloth's sheet, a lattice's hull) that it may
-- touch is pushed out to exactly r from the triangle's closest point q = sum b_i x_i,
-- along the line from q (or the face normal, towards the side it was on at the
-- substep's start, when it went through); the point moves w_p depth / W and corner i
-- -b_i w_i depth / W, W = w_p + sum b_i^2 w_i (XPBD, compliance 0), so the corrections
-- carry no momentum; the velocity pass removes the approach speed the same way. So:
--  * on a pinned sheet (nothing else moving it) a resting particle ends every substep
--    at exactly r, to round-off (1e-12 is ~1e4 ulps), and its contact reads m g;
--  * the momentum of a free cloth and a loose particle is unchanged to round-off: each
--    velocity is (x - x_prev)/h, an ulp of x over h = 1/600 is ~1e-13, times 1e2
--    particles: 1e-10 absolute is round-off, a correction off by a weight is ~1e-2.
-- The particles here are much smaller than the bodies' spacing: without triangle
-- contacts (contacts = false) each of these scenes fails its check, and so it does
-- with the triangle contacts switched off in the code.

local function pos(w, p) return { w:position(p) } end

-- a pinned cloth of 5 x 5 particles 0.5 m apart in y = 0 (x, z in [-1, 1]), radius 0.02,
-- and a particle of radius 0.02 dropped from 0.5 m at (x, z)
local function sheet_drop(x, z, contacts)
  local w = wobble.world{ contacts = contacts }
  local c = w:cloth{ origin = {-1, 0, -1}, size = {2, 2}, res = {5, 5}, mass = 1, radius = 0.02 }
  c:pin_where(function() return true end)
  local p = w:particle{ pos = {x, 0.5, z}, radius = 0.02, mass = 0.1 }
  return w, p
end

test("a small particle dropped on a coarse pinned cloth rests on it at its radius", function()
  -- inside a triangle, on a diagonal (an edge shared by two triangles), on a grid line
  for _, at in ipairs{ {0.13, 0.21}, {0.2, 0.2}, {0.0, 0.31} } do
    local w, p = sheet_drop(at[1], at[2])
    local lowest = math.huge
    w:run{ frames = 90, on_frame = function(w) lowest = math.min(lowest, pos(w, p)[2]) end }
    local x = pos(w, p)
    expect.near(x[1], at[1], 1e-12, "no sideways drift")
    expect.near(x[3], at[2], 1e-12, "no sideways drift")
    expect.near(x[2], 0.02, 1e-12, "rests at its radius")
    -- it landed at 3.1 m/s: 0.0052 m per substep; the velocity pass stops it in the
    -- substep it touches, so at a frame's end it is never below its radius
    expect.ge(lowest, 0.02 - 1e-12, "never below its radius at a frame's end")
    local _, vy = w:velocity(p)
    expect.near(vy, 0, 1e-9, "at rest")
    -- the contact's normal force: depth g h^2 over h^2 times m
    local f = 0
    for _, c in ipairs(w:contacts()) do
      if c.kind == "triangle" and c.a == p then f = f + c.force end
    end
    expect.near(f, 0.1 * 9.81, 1e-9, "it weighs m g on the sheet")
    expect.ge(w:stats().particle_contacts, 1)
  end
end)

test("contacts = false: the same particle falls through the cloth", function()
  local w, p = sheet_drop(0.13, 0.21, false)
  w:run{ frames = 90 }
  expect.lt(pos(w, p)[2], -1, "fell through")
end)

-- a coarse soft block (3 x 3 x 3 particles 0.5 m apart, radius 0.02) on the ground and
-- a small rigid-ish block (2 x 2 x 2 particles 0.06 m apart, radius 0.01) dropped on the
-- middle of a top quad, between the big block's particles
local function block_drop(contacts)
  local w = wobble.world{ substeps = 10, iterations = 2, contacts = contacts }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
  local big = w:lattice{ min = {-0.5, 0.02, -0.5}, max = {0.5, 1.02, 0.5}, res = {3, 3, 3}, mass = 4,
                         compliance = 1e-4, radius = 0.02, friction = 0.5 }
  local small = w:lattice{ min = {0.2, 1.4, 0.22}, max = {0.26, 1.46, 0.28}, res = {2, 2, 2}, mass = 0.05,
                           radius = 0.01, friction = 0.5 }
  return w, big, small
end

-- the height of the big block's top face under (x, z): its quad's corners interpolated
-- bilinearly (the top layer is j = 3, particles ordered i + 3 (j + 3 k))
local function top_height(w, big, x, z)
  local y = -math.huge
  for k = 0, 1 do
    for i = 0, 1 do
      y = math.max(y, pos(w, big.particles[1 + (i + 1) + 3 * (2 + 3 * (k + 1))])[2])
    end
  end
  return y
end

test("a small body landing on a coarse soft block's hull rests on it", function()
  local w, big, small = block_drop()
  w:run{ frames = 150 }
  local lo = math.huge
  for _, p in ipairs(small.particles) do lo = math.min(lo, pos(w, p)[2]) end
  -- the top face sags under it; the small body's lowest particle is at its radius above
  -- the face, itself within the sag of the top layer (a few mm at this compliance)
  local top = -math.huge
  for k = 0, 2 do
    for i = 0, 2 do top = math.max(top, pos(w, big.particles[1 + i + 3 * (2 + 3 * k)])[2]) end
  end
  expect.gt(lo, top - 0.02, "on the top face, not inside the block")
  expect.lt(lo, top + 0.05, "resting on it")
  local _, vy = w:velocity(small.particles[1])
  expect.near(vy, 0, 1e-3, "at rest")
  local n = 0
  for _, c in ipairs(w:contacts()) do if c.kind == "triangle" then n = n + 1 end end
  expect.gt(n, 0, "held by triangle contacts")
  -- without contacts it falls through the block to the ground
  local w2, _, small2 = block_drop(false)
  w2:run{ frames = 150 }
  expect.lt(pos(w2, small2.particles[1])[2], 0.2, "without contacts: through the block")
end)

-- a cloth's triangles, as the builder makes them (nx x nz particles, split along the
-- shear diagonals); their normals point up (+y) for a cloth made flat
local function cloth_triangles(c, nx, nz)
  local t = {}
  local function id(i, j) return c.particles[1 + i + nx * j] end
  for j = 0, nz - 2 do
    for i = 0, nx - 2 do
      local a, b, cc, e = id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)
      if (i + j) % 2 == 0 then t[#t + 1] = {a, e, cc}; t[#t + 1] = {a, cc, b}
      else t[#t + 1] = {a, e, b}; t[#t + 1] = {b, e, cc} end
    end
  end
  return t
end

-- signed distance of x from triangle t's plane when x projects inside it (else nil)
local function side(w, t, x)
  local a, b, c = pos(w, t[1]), pos(w, t[2]), pos(w, t[3])
  local function sub(u, v) return {u[1] - v[1], u[2] - v[2], u[3] - v[3]} end
  local function dot(u, v) return u[1] * v[1] + u[2] * v[2] + u[3] * v[3] end
  local function cross(u, v) return {u[2] * v[3] - u[3] * v[2], u[3] * v[1] - u[1] * v[3], u[1] * v[2] - u[2] * v[1]} end
  local e1, e2, d = sub(b, a), sub(c, a), sub(x, a)
  local n = cross(e1, e2)
  local nn = dot(n, n)
  if nn == 0 then return nil end
  local u = dot(cross(d, e2), n) / nn
  local v = dot(cross(e1, d), n) / nn
  if u < 0 or v < 0 or u + v > 1 then return nil end
  return dot(d, n) / math.sqrt(nn)
end

test("a moving cloth hitting a loose particle: momentum exact, the particle carried along", function()
  local function scene(contacts)
    local w = wobble.world{ gravity = {0, 0, 0}, contacts = contacts }
    local c = w:cloth{ origin = {-1, 1, -1}, size = {2, 2}, res = {5, 5}, mass = 2, radius = 0.02,
                       compliance = 1e-5 }
    for _, p in ipairs(c.particles) do w:set_velocity(p, 0.3, -2, 0.1) end
    local p = w:particle{ pos = {0.13, 0, 0.21}, radius = 0.02, mass = 0.3 }
    return w, c, p
  end
  local w, c, p = scene()
  local tris = cloth_triangles(c, 5, 5)
  local px0, py0, pz0 = w:momentum()
  local over = 0
  w:run{ frames = 90, on_frame = function(w)
    local px, py, pz = w:momentum()
    expect.near(px, px0, 1e-10, "momentum x")
    expect.near(py, py0, 1e-10, "momentum y")
    expect.near(pz, pz0, 1e-10, "momentum z")
    -- under the sheet (the triangles' normals point up), never above it
    for _, t in ipairs(tris) do
      local s = side(w, t, pos(w, p))
      if s and s > over then over = s end
    end
  end }
  expect.eq(over, 0, "never above a triangle it lies under")
  -- carried along: moving down with the sheet
  local _, vy = w:velocity(p)
  expect.lt(vy, -1, "carried along by the cloth")
  -- without contacts the sheet passes it by and it stays at rest
  local w2, _, p2 = scene(false)
  w2:run{ frames = 90 }
  expect.eq(select(2, w2:velocity(p2)), 0)
end)

-- a strip of cloth 2 x 1 m (9 x 5 particles 0.25 m apart, radius 0.02) lying on the
-- ground, self-colliding; its left edge is pinned and carried over in a half circle to
-- 0.08 m above the right half, where the rest of the left half falls onto it: a fold
local function fold(threads, self_collide)
  local w = wobble.world{ substeps = 10, iterations = 2, threads = threads }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
  local c = w:cloth{ origin = {-1, 0.02, -0.5}, size = {2, 1}, res = {9, 5}, mass = 1, radius = 0.02,
                     compliance = 1e-6, self_collide = self_collide, friction = 0.3 }
  local edge = {}
  for j = 0, 4 do edge[#edge + 1] = c.particles[1 + 9 * j] end
  return w, c, edge
end

-- the fold, 150 frames; with `check`, counts the particles that went through a triangle
-- of the sheet: the side of a particle near a triangle (within 0.1 m of its plane and
-- over it) flipping from one frame to the next (a frame moves nothing 0.1 m here)
local function run_fold(w, c, edge, check)
  local tris = cloth_triangles(c, 9, 5)
  local last, crossings = {}, 0
  w:run{ frames = 150, on_frame = function(w, f)
    local th = math.min(f / 100, 1) * math.pi
    for j, p in ipairs(edge) do
      -- half a spacing aside in z: the folded particles land between the bottom layer's,
      -- where only its triangles can hold them
      local z = -0.75 + 0.25 * j + 0.125 * math.min(f / 100, 1)
      w:pin(p, {-0.1 - 0.9 * math.cos(th), 0.02 + 0.06 * math.min(f / 10, 1) + 0.9 * math.sin(th), z})
    end
    if not check then return end
    for pi, p in ipairs(c.particles) do
      local x = pos(w, p)
      for ti, t in ipairs(tris) do
        if p ~= t[1] and p ~= t[2] and p ~= t[3] then
          local s = side(w, t, x)
          local key = pi * 1000 + ti
          if s and math.abs(s) < 0.1 then
            if last[key] and last[key] * s < 0 then crossings = crossings + 1 end
            last[key] = s
          else
            last[key] = nil
          end
        end
      end
    end
  end }
  return crossings
end

-- the lowest height of the folded part (columns 0..2) over the bottom layer's triangles
-- (columns 5..8, normals up), relative to the contact radius
local function fold_gap(w, c)
  local lowest = math.huge
  for _, t in ipairs(cloth_triangles(c, 9, 5)) do
    local bottom = true
    for k = 1, 3 do bottom = bottom and (t[k] - c.particles[1]) % 9 >= 5 end
    if bottom then
      for j = 0, 4 do
        for i = 0, 2 do
          local s = side(w, t, pos(w, c.particles[1 + i + 9 * j]))
          if s then lowest = math.min(lowest, s) end
        end
      end
    end
  end
  return lowest
end

test("self-collision: a coarse cloth folded onto itself never passes through its own sheet", function()
  local w, c, edge = fold(1, true)
  expect.eq(run_fold(w, c, edge, true), 0, "particles that went through a triangle of the sheet")
  -- folded: the left half lies on the right half at the contact radius, 0.02 m. Less by
  -- what moves the bottom layer after the contact pass of a substep: the ground pushes
  -- back up the corners the contact pushed down, the links pull (measured 2e-4 m; 1e-3
  -- allowed, half the radius would be a particle sinking through)
  local gap = fold_gap(w, c)
  expect.gt(gap, 0.02 - 1e-3, "on top of the bottom layer, a radius above it")
  expect.lt(gap, 0.1, "lying on it")
  -- the same fold without self-collision ends in the bottom layer, on the ground
  local w2, c2, e2 = fold(1, false)
  run_fold(w2, c2, e2, false)
  expect.lt(fold_gap(w2, c2), 0.01, "without self-collision: not on top")
end)

test("determinism with triangle contacts: the same hash with 1 and 2 threads", function()
  local w1, c1, e1 = fold(1, true)
  run_fold(w1, c1, e1, false)
  local w2, c2, e2 = fold(2, true)
  run_fold(w2, c2, e2, false)
  expect.eq(w1:hash(), w2:hash())
  expect.gt(w1:stats().particle_contacts, 0)
end)
