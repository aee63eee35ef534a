-- render_hull_radius.lua: a body's closed hull is drawn where its particles' spheres end
-- (out along the normals by each particle's contact radius), so bodies resting on each
-- other or on a collider look touching; an open surface (a cloth) stays through the
-- particle centres, since a sheet has no outside.

local W, H = 160, 120
local r = wobble.renderer{ width = W, height = H, samples = 4 }

local function at(p)
  local x, y = r:project(p[1], p[2], p[3])
  expect.truthy(x and x >= 0 and x < W and y >= 0 and y < H, "point inside the frame")
  return r:pixel(x, y)
end

local function is_sky(cr, _, cb) return cb > cr + 20 end
local function is_orange(cr, cg, cb) return cr > cg + 40 and cr > cb + 40 end   -- the first surface's colour
local opts = { grid = false, constraints = false, particles = false }

-- a 1 m block, centres from -0.5 to 0.5 in x and z, 0 to 1 in y, seen side-on along z
local function block(radius)
  local w = wobble.world{ gravity = {0, 0, 0} }
  w:lattice{ min = {-0.5, 0, -0.5}, max = {0.5, 1, 0.5}, res = {5, 5, 5}, radius = radius }
  r:camera{ eye = {0, 0.5, 4}, target = {0, 0.5, 0} }
  r:draw(w, opts)
end

test("a lattice's hull reaches out to its particles' radius", function()
  block(0.1)
  -- inside the centres' hull: the block either way
  expect.truthy(is_orange(at{ 0.4, 0.5, 0.5 }), "inside the centres' hull")
  -- outside the centres' hull (x 0.5) but inside centre + radius (0.6), on each side,
  -- above and below: the block's colour
  for _, p in ipairs{ { 0.55, 0.5, 0.5 }, { -0.55, 0.5, 0.5 }, { 0, 1.05, 0.5 }, { 0, -0.05, 0.5 } } do
    local cr, cg, cb = at(p)
    expect.truthy(is_orange(cr, cg, cb), string.format("at (%g, %g): the block (%d,%d,%d)", p[1], p[2], cr, cg, cb))
  end
  -- beyond the radius: sky (the offset is the radius, not more)
  expect.truthy(is_sky(at{ 0.68, 0.5, 0.5 }), "beyond centre + radius: sky")
end)

test("with radius 0 the hull is through the centres", function()
  block(0)
  expect.truthy(is_orange(at{ 0.4, 0.5, 0.5 }), "inside the centres' hull")
  expect.truthy(is_sky(at{ 0.55, 0.5, 0.5 }), "just outside the centres' hull: sky")
  expect.truthy(is_sky(at{ 0, 1.05, 0.5 }), "just above it: sky")
end)

test("a cloth (an open surface) stays through its particle centres", function()
  -- a level sheet at y = 1, z -0.5..0.5, seen from above and in front: offset by its
  -- radius (0.1) either way along its normal, the points near its front and back
  -- edges would no longer be covered
  local w = wobble.world{ gravity = {0, 0, 0} }
  w:cloth{ origin = {-0.5, 1, -0.5}, size = {1, 1}, res = {5, 5}, radius = 0.1 }
  r:camera{ eye = {0, 2, 4}, target = {0, 1, 0} }
  r:draw(w, opts)
  expect.truthy(is_orange(at{ 0, 1, 0.45 }), "near its front edge: the sheet")
  expect.truthy(is_orange(at{ 0, 1, -0.45 }), "near its back edge: the sheet")
end)
