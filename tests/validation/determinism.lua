-- determinism.lua: the same scene and options give bit-identical states, whatever
-- the thread count (DESIGN §2). w:hash() is an FNV-1a hash of the whole state, so
-- equal hashes mean equal bits (up to hash collisions, 2^-64).
--
-- The scene is large enough for the parallel path: colour batches of >= 512
-- constraints are split across threads (48 x 48 cloth: ~2300 structural links per
-- direction, batches of ~1100). Exact equality, no tolerance: Gauss-Seidel runs the
-- batches in a fixed order and no two constraints of a batch touch the same movable
-- particle, so the order inside a batch cannot change a single bit.

local function scene(threads, solver)
  local w = wobble.world{ threads = threads, solver = solver, iterations = 2, substeps = 8 }
  local cloth = w:cloth{ origin = { -1, 1, -1 }, size = { 2, 2 }, res = { 48, 48 }, mass = 1,
                         compliance = 1e-6, damping = 0.05, bend = 1e-3 }
  w:pin(cloth.particles[1])
  w:collider{ shape = "sphere", center = { 0.1, 0, 0 }, radius = 0.6, friction = 0.3 }
  w:collider{ shape = "plane", normal = { 0, 1, 0 }, offset = -0.8, restitution = 0.5 }
  local box = w:collider{ shape = "box", center = { -0.8, -0.5, 0 }, half = { 0.2, 0.2, 0.2 } }
  box:set_velocity(0.5, 0.3, 0)
  local rope = w:rope{ from = { 0.5, 1.5, 0 }, to = { 1.5, 1.5, 0 }, segments = 30, compliance = 1e-5 }
  w:pin(rope.particles[1])
  return w
end

local function run(threads, solver, frames)
  local w = scene(threads, solver)
  local trace = {}
  w:run{ frames = frames, on_frame = function(w, f)
    if f % 10 == 0 then trace[#trace + 1] = w:hash() end
  end }
  return w:hash(), trace, w
end

test("two runs of the same scene: identical hashes", function()
  local h1, t1 = run(1, "gauss-seidel", 40)
  local h2, t2 = run(1, "gauss-seidel", 40)
  expect.eq(h1, h2)
  expect.eq(t1, t2, "hash every 10 frames")
end)

test("threads = 1 vs threads = 2: identical hashes (Gauss-Seidel)", function()
  local h1, t1, w = run(1, "gauss-seidel", 40)
  local h2, t2 = run(2, "gauss-seidel", 40)
  expect.eq(h1, h2)
  expect.eq(t1, t2, "hash every 10 frames")
  -- the scene did something: it moved and touched the sphere
  expect.gt(w:stats().contacts, 0, "contacts")
end)

test("threads = 1 vs threads = 2: identical hashes (Jacobi)", function()
  local h1 = run(1, "jacobi", 30)
  local h2 = run(2, "jacobi", 30)
  expect.eq(h1, h2)
end)

test("the hash sees the smallest change", function()
  -- one ulp of one coordinate of one particle changes the hash
  local a, b = scene(1, "gauss-seidel"), scene(1, "gauss-seidel")
  a:run{ frames = 5 }
  b:run{ frames = 5 }
  expect.eq(a:hash(), b:hash())
  local x, y, z = b:position(100)
  -- |x| 2^-52 is at least one ulp of x (x != 0: the cloth spans x in [-1, 1] and
  -- particle 100 is not on x = 0)
  local x2 = x + math.abs(x) * 2 ^ -52
  expect.truthy(x2 ~= x, "a different double")
  b:set_position(100, x2, y, z)
  expect.truthy(a:hash() ~= b:hash(), "hash changed")
end)
