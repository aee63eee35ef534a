-- momentum.lua: internal constraints conserve linear momentum.
--
-- With gravity 0, no pins, no colliders and no world damping, only distance
-- constraints act. Each XPBD projection moves its two particles by -w_a s d and
-- +w_c s d (w = 1/m): the momentum change m_a(-w_a s d) + m_c(w_c s d) is exactly 0,
-- and so is the change from the constraint damping term (it only changes s). The
-- prediction x += h v and the update v = (x - x_prev)/h do not change sum m v either.
-- So the total momentum is conserved up to round-off.
--
-- Round-off bound: per substep every coordinate x_i takes at most
-- 2 (deg_i iterations + 1) roundings of relative size eps (deg_i = constraints at i),
-- and the velocity update turns a position error dx into dx/h; errors made in a
-- substep carry over to the next one in x and x_prev alike, so only fresh errors reach
-- the momentum: |dP| <= n_sub * 2 (deg_max iterations + 2) eps sum_i m_i |x_i|max / h.

local eps = 2.0 ^ -52

-- a pseudo-random generator of our own (the same numbers on every platform)
local function lcg(seed)
  local s = seed
  return function()
    s = (s * 1103515245 + 12345) % 2147483648
    return s / 2147483648 - 0.5
  end
end

local function scene(solver, iterations)
  local w = wobble.world{ gravity = { 0, 0, 0 }, substeps = 10, iterations = iterations,
                          solver = solver, damping = 0 }
  local rnd = lcg(7)
  -- a cloth with shear and bend links of different stiffness, and a rope across it;
  -- unequal masses (rope particles 5/13 kg, cloth particles 1/81 kg) and unequal
  -- constraint counts per particle (2 on the rope, up to 10 in the cloth)
  local cloth = w:cloth{ origin = { -0.5, 0, -0.5 }, size = { 1, 1 }, res = { 9, 9 }, mass = 1,
                         compliance = 1e-5, damping = 0.01, bend = 1e-3 }
  local rope = w:rope{ from = { -0.5, 0.3, 0 }, to = { 0.5, 0.3, 0 }, segments = 12, mass = 5,
                       compliance = 0 }
  w:distance(rope.particles[1], cloth.particles[1], { compliance = 1e-4 })
  w:distance(rope.particles[13], cloth.particles[81], { compliance = 0 })
  for id = 1, w:particle_count() do
    w:set_velocity(id, 2 * rnd(), 2 * rnd(), 2 * rnd())
  end
  return w
end

local function check(solver, iterations)
  local w = scene(solver, iterations)
  local p0 = { w:momentum() }
  local n_sub, frames = 0, 120
  local sum_mx = 0 -- sum m |x|, largest over the run
  local deg_max = 10 -- cloth: 4 structural + 2 shear + 4 bend, plus one cross link
  w:run{ frames = frames, on_frame = function(w)
    local s = 0
    for id = 1, w:particle_count() do
      local x, y, z = w:position(id)
      s = s + w:mass(id) * (math.abs(x) + math.abs(y) + math.abs(z))
    end
    sum_mx = math.max(sum_mx, s)
  end }
  n_sub = frames * 10
  local h = w:dt() / 10
  local tol = n_sub * 2 * (deg_max * iterations + 2) * eps * sum_mx / h
  local p1 = { w:momentum() }
  for i = 1, 3 do
    expect.near(p1[i], p0[i], tol, string.format("%s, %d iterations: momentum[%d]", solver, iterations, i))
  end
  -- the constraints were working
  expect.gt(w:stats().projections, 0)
  return tol, p0
end

test("Gauss-Seidel: momentum conserved to round-off", function()
  local tol, p0 = check("gauss-seidel", 1)
  check("gauss-seidel", 4)
  -- the bound is round-off, not physics: far below the momentum itself
  expect.lt(tol, 1e-6 * math.sqrt(p0[1] ^ 2 + p0[2] ^ 2 + p0[3] ^ 2))
end)

test("Jacobi: momentum conserved to round-off", function()
  -- internal forces come in equal and opposite pairs whatever the solver: a Jacobi
  -- sweep must apply each constraint's correction to both its ends with the same
  -- multiplier (scaling a particle's summed corrections by its own constraint count
  -- breaks the pairs wherever two linked particles have different counts)
  check("jacobi", 1)
  check("jacobi", 4)
end)
