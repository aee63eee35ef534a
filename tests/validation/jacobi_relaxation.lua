-- jacobi_relaxation.lua: what the relaxation factor omega does to a Jacobi sweep.
--
-- Jacobi computes every correction from the same positions, scales each by
-- omega / max(n_a, n_b) (n: the number of constraints of a movable end) and applies
-- them at once. One frame of one substep and one iteration, no gravity and no
-- velocity, leaves the particles exactly where that one sweep puts them, so the
-- results below follow by hand (rigid links, alpha = 0, equal masses):
--
-- * one link of length L and rest r between two free particles: each end moves by
--   omega (r - L) / 2 along the link, so the new length is L + omega (r - L);
--   omega = 1 lands on r in one sweep, omega = 0.5 halfway, omega = 1.5 overshoots.
-- * a chain a - b - c, both links of length L along x: the middle particle has two
--   links, so both corrections are halved: a moves by omega (L - r) / 4 towards b,
--   c the same towards b, and b, pulled equally both ways, stays put.
-- Tolerances are rounding only (1e-12 m on values near 1).

local function one_frame(solver, omega, xs, rest)
  local w = wobble.world{ solver = solver, relaxation = omega, substeps = 1, iterations = 1,
                          gravity = {0, 0, 0} }
  local ids = {}
  for i, x in ipairs(xs) do ids[i] = w:particle{ pos = {x, 0, 0}, mass = 1 } end
  for i = 1, #xs - 1 do w:distance(ids[i], ids[i + 1], { rest = rest }) end
  w:step()
  local out = {}
  for i, p in ipairs(ids) do out[i] = w:position(p) end
  return out
end

test("one link: the new length is L + omega (r - L)", function()
  local L, r = 1.5, 1.0
  for _, omega in ipairs{ 1, 0.5, 1.5, 0.25 } do
    local x = one_frame("jacobi", omega, { 0, L }, r)
    expect.near(x[2] - x[1], L + omega * (r - L), 1e-12, "omega = " .. omega)
    expect.near(x[1], omega * (L - r) / 2, 1e-12, "first end, omega = " .. omega)
  end
end)

test("a chain: corrections shared by the busier end, omega / 2 each", function()
  local L, r = 1.2, 1.0
  for _, omega in ipairs{ 1, 0.5, 1.8 } do
    local x = one_frame("jacobi", omega, { 0, L, 2 * L }, r)
    expect.near(x[1], omega * (L - r) / 4, 1e-12, "a, omega = " .. omega)
    expect.near(x[2], L, 1e-12, "b stays, omega = " .. omega)
    expect.near(x[3], 2 * L - omega * (L - r) / 4, 1e-12, "c, omega = " .. omega)
  end
end)

test("Gauss-Seidel ignores relaxation", function()
  local a = one_frame("gauss-seidel", 1, { 0, 1.2, 2.4 }, 1)
  local b = one_frame("gauss-seidel", 0.5, { 0, 1.2, 2.4 }, 1)
  expect.eq(a, b)
  -- one rigid link projected in place: exactly the rest length
  local x = one_frame("gauss-seidel", 0.5, { 0, 1.5 }, 1)
  expect.near(x[2] - x[1], 1, 1e-12)
end)
