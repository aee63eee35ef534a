-- neo_stiff.lua: a Neo-Hookean solid too stiff for its substep is said, not silent (tet.c).
--
-- The bar of neo_hookean.lua (1 m, 0.1 x 0.1 m, 1 kg: 100 kg/m^3, cells 0.05 m, 480 tets)
-- hangs from its top face. XPBD with one iteration holds it while the substep h is shorter
-- than about twice the time a wave sqrt(E/density) takes to cross a tet; past it the
-- linearised 2x2 step of each tet overshoots towards C_D = 0 and the bar collapses within
-- the first frame (measured: E = 1e7 at 40 substeps, h/t = 4.05, ends 0.10 m tall with 220
-- of its 480 tets inverted; E = 2e5 at 10 substeps, h/t = 2.3, holds; 4e5, h/t = 3.2, does
-- not). tet.c computes h/t at prepare time from E, the rest volumes, shapes and corner
-- masses and warns once, naming the substeps that would do; at a frame's end it also warns
-- once when more than 1% of the tets are inverted.
--
-- Checked: the stiff bar warns at its first step, with a substep count; following that
-- advice (the suggested substeps) the same bar keeps its 1 m within 2 cm and warns
-- nothing (the linear stretch M g L / 2 E A is 0.05 mm at 1e7: 2 cm is the coarse bar's
-- settling, not elasticity); a collapsed bar also gets the inverted-tets warning, each
-- warning once, not per step; the soft bar of neo_hookean.lua (h/t = 0.4) warns nothing.
-- Without the prepare check the first test fails (no warning); without the frame-end
-- check the third.

local function bar(young, substeps)
  local w = wobble.world{ gravity = { 0, -9.81, 0 }, substeps = substeps, iterations = 1, damping = 5 }
  local b = w:lattice{ min = { -0.05, -1, -0.05 }, max = { 0.05, 0, 0.05 }, res = { 3, 21, 3 }, mass = 1,
                       tets = true, young = young, poisson = 0.3, collide = false }
  for k = 0, 2 do for i = 0, 2 do w:pin(b.first + i + (20 + k * 21) * 3) end end
  return w
end

local function height(w)
  local _, y0, _, _, y1 = w:bounds()
  return y1 - y0
end

local suggested

test("a bar too stiff for its substep warns at its first step, naming the substeps needed", function()
  local w = bar(1e7, 40)
  print("expected on stderr: a warning that Neo-Hookean tets are inverted (this bar is too stiff on purpose)")
  w:step()
  local n, msg = w:warnings()
  expect.ge(n, 1, "warned")
  expect.truthy(msg:find("Neo%-Hookean tets"), "names the type: " .. tostring(msg))
  suggested = tonumber(msg:match("raise substeps to about (%d+)"))  -- both warnings repeat it
  expect.truthy(suggested, "names the substeps: " .. tostring(msg))
  expect.ge(suggested, 41, "more than it has")
  expect.lt(suggested, 400, "not absurdly many")
end)

test("with the suggested substeps the same bar keeps its height and warns nothing", function()
  local w = bar(1e7, suggested or 82)
  for _ = 1, 120 do w:step() end
  expect.near(height(w), 1, 0.02, "height, m")
  expect.eq(w:warnings(), 0, "no warning")
end)

test("a collapsed bar warns that its tets are inverted, each warning once", function()
  local w = bar(1e7, 40)
  print("expected on stderr: a warning that Neo-Hookean tets are inverted (this bar is too stiff on purpose)")
  for _ = 1, 120 do w:step() end
  expect.lt(height(w), 0.5, "the bar collapsed (what the warnings are about)")
  local n, msg = w:warnings()
  expect.eq(n, 2, "the substep warning and the inverted-tets one, once each")
  expect.truthy(msg:find("inverted"), "the last names inverted tets: " .. tostring(msg))
end)

test("a bar within the limit warns nothing", function()
  local w = bar(1e5, 40)
  for _ = 1, 120 do w:step() end
  expect.near(height(w), 1, 0.02, "height, m")
  expect.eq(w:warnings(), 0, "no warning")
end)
