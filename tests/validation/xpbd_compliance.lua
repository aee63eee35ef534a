-- xpbd_compliance.lua: XPBD compliance is a physical spring constant.
--
-- A mass m hangs from an immovable particle by a distance constraint of compliance
-- alpha (stiffness k = 1/alpha). Hooke's law: it settles at a stretch of m g alpha,
-- and the constraint force is m g, whatever the substeps and iterations. In XPBD this
-- holds exactly at rest: each substep the prediction adds g h^2 of stretch, the update
-- dlambda = (-C - alpha~ lambda)/(w + alpha~), alpha~ = alpha/h^2, must remove it, so
-- C~ = g h^2 (w + alpha~)/w = g h^2 + m g alpha: stretch m g alpha, lambda = -m g h^2.
-- (Plain PBD with a stiffness factor in (0,1] applied per iteration would settle at a
-- stretch depending on h and the iteration count: that is what XPBD fixes.)
--
-- Settling: the constraint's own damping beta (Macklin et al. 2016 eq. 26) is a
-- viscous force -beta dC/dt along the link; it vanishes at rest so it does not move
-- the equilibrium. The oscillation envelope decays as exp(-beta t / 2m) (implicit
-- Euler only adds damping). Tolerance: the initial offset m g alpha times that
-- envelope (with half the rate, for margin) plus round-off of coordinates of size ~1
-- (a few 1e-16; 1e-12 is used).

local g, m, alpha = 9.81, 2.0, 1e-3

local function hang(substeps, iterations, opts)
  local w = wobble.world{ gravity = { 0, -g, 0 }, dt = 1 / 60, substeps = substeps,
                          iterations = iterations, damping = opts.world_damping or 0 }
  local top = w:particle{ pos = { 0, 2, 0 }, mass = 0 }
  local bob = w:particle{ pos = { 0, 1, 0 }, mass = m }
  local c = w:distance(top, bob, { compliance = alpha, damping = opts.beta or 0 })
  w:run{ seconds = opts.seconds }
  local _, y = w:position(bob)
  return 1 - y, c:force(), w -- stretch: length (2 - y) minus rest 1
end

test("hanging mass settles at a stretch of m g alpha for any (substeps, iterations)", function()
  local beta, t = 40, 5
  local tol = m * g * alpha * 2 * math.exp(-(beta / (2 * m)) * t / 2) + 1e-12
  for _, si in ipairs{ { 1, 1 }, { 4, 1 }, { 10, 1 }, { 5, 4 }, { 20, 10 }, { 40, 3 } } do
    local s, f = hang(si[1], si[2], { beta = beta, seconds = t })
    local what = string.format("substeps %d, iterations %d", si[1], si[2])
    expect.near(s, m * g * alpha, tol, what .. ": stretch")
    -- force() = |lambda| / h^2 = m g; a stretch error ds changes it by at most ds/alpha
    expect.near(f, m * g, tol / alpha + 1e-9, what .. ": force")
  end
end)

test("stretch is linear in compliance and in mass (Hooke)", function()
  for _, a in ipairs{ 1e-4, 1e-3, 1e-2 } do
    local w = wobble.world{ gravity = { 0, -g, 0 }, substeps = 10 }
    local top = w:particle{ pos = { 0, 0, 0 }, mass = 0 }
    local bob = w:particle{ pos = { 0, -1, 0 }, mass = 0.5 }
    -- damping 20 N s/m on 0.5 kg: envelope exp(-20 t), 6 s
    w:distance(top, bob, { compliance = a, damping = 20 })
    w:run{ seconds = 6 }
    local _, y = w:position(bob)
    expect.near(-y - 1, 0.5 * g * a, 0.5 * g * a * 2 * math.exp(-20 * 6 / 2) + 1e-12,
                "compliance " .. a)
  end
end)

test("world damping does not move the static equilibrium", function()
  -- World damping is a drag on velocity (v *= 1 - d h per substep). Drag vanishes at
  -- rest: the hanging mass must still weigh m g and stretch by m g alpha. Envelope
  -- exp(-d t / 2) = exp(-40) after 8 s with d = 10 (plus implicit Euler's own damping).
  local d, t = 10, 8
  local tol = m * g * alpha * 2 * math.exp(-d * t / 2) + 1e-12
  for _, s in ipairs{ 1, 10 } do
    local st, f = hang(s, 1, { world_damping = d, seconds = t })
    expect.near(st, m * g * alpha, tol, "substeps " .. s .. ": stretch")
    expect.near(f, m * g, tol / alpha + 1e-9, "substeps " .. s .. ": force")
  end
end)

test("two-link chain: static forces 2 m g and m g, Gauss-Seidel and Jacobi", function()
  -- Two masses m in series under an immovable particle, links of compliance alpha:
  -- Newton gives tensions 2 m g (top) and m g (bottom), stretches 2 m g alpha and
  -- m g alpha. This is the fixed point of the XPBD iteration whatever the solver,
  -- provided the multipliers describe the corrections actually applied. The
  -- iteration converges geometrically; 200 iterations per substep leave even a slow
  -- contraction rate of 0.9 at 1e-9 of the initial error, and the constraint damping
  -- (beta = 20 N s/m on 1 kg, envelope exp(-10 t), 6 s) removes the transient.
  -- Tolerance 1e-6 relative: far above both, far below any O(1) error of the method.
  for _, solver in ipairs{ "gauss-seidel", "jacobi" } do
    local w = wobble.world{ gravity = { 0, -g, 0 }, solver = solver, iterations = 200, substeps = 10 }
    local a = w:particle{ pos = { 0, 0, 0 }, mass = 0 }
    local b = w:particle{ pos = { 0, -1, 0 }, mass = 1 }
    local c = w:particle{ pos = { 0, -2, 0 }, mass = 1 }
    local top = w:distance(a, b, { compliance = alpha, damping = 20 })
    local bot = w:distance(b, c, { compliance = alpha, damping = 20 })
    w:run{ seconds = 6 }
    expect.rel(top:force(), 2 * g, 1e-6, solver .. ": top link force")
    expect.rel(bot:force(), g, 1e-6, solver .. ": bottom link force")
    expect.rel(top:length() - 1, 2 * g * alpha, 1e-6, solver .. ": top link stretch")
    expect.rel(bot:length() - 1, g * alpha, 1e-6, solver .. ": bottom link stretch")
  end
end)
