-- A hand-built rope, the reference workflow: w:particle + w:distance, particles 1 cm
-- apart, pinned at one end, released horizontal and swinging under gravity. Every option
-- is the default a user would have (radius 0.02, contacts on, 10 substeps, links rigid).
local N, SPACING, Y0 = 50, 0.01, 1.0          -- 50 links: a 0.5 m rope
local L = N * SPACING

local function build()
  -- 40 substeps x 4 iterations: rigid links converge only with enough of them (docs/physics.md,
  -- "Convergence"); at the default 10 x 1 this rope stretches to 99% while it swings
  local w = wobble.world{ substeps = 40, iterations = 4 }
  local ids, links = {}, {}
  for i = 0, N do ids[#ids + 1] = w:particle{ pos = { i * SPACING, Y0, 0 }, mass = 0.01 } end
  for i = 1, N do links[i] = w:distance(ids[i], ids[i + 1]) end
  w:pin(ids[1])
  return w, ids, links
end

test("hand-built rope swinging: every link stays within 3% of its rest length", function()
  local w, ids, links = build()
  local worst, worst_t = 0, 0
  w:run{ seconds = 2, on_frame = function(w, f, t)
    local s = w:max_strain()
    if s > worst then worst, worst_t = s, t end
  end }
  print(string.format("max strain %.4f at t = %.2f s; warnings %d", worst, worst_t, (w:warnings())))
  -- rigid links (compliance 0): the only stretch is the solver's unconverged error; a
  -- rope swinging at ~3 m/s with 10 substeps should keep it to a few %
  expect.lt(worst, 0.03, "max strain over the swing")
  expect.eq((w:warnings()), 0, "no numerical warnings")
end)

test("hand-built rope: the free end never gets further than L(1+3%) from the pin", function()
  local w, ids = build()
  local far = 0
  w:run{ seconds = 2, on_frame = function(w)
    local x, y, z = w:position(ids[#ids])
    far = math.max(far, math.sqrt(x * x + (y - Y0) ^ 2 + z * z))
  end }
  print(string.format("furthest reach %.4f m (rope %.2f m)", far, L))
  expect.le(far, L * 1.03, "reach of the free end")
end)

test("hand-built rope: it swings down (the free end passes below the pin) and gains no energy", function()
  local w, ids = build()
  local ke0, pe0 = w:energy()
  local e0 = ke0 + pe0
  local lowest, emax = math.huge, -math.huge
  w:run{ seconds = 2, on_frame = function(w)
    local _, y = w:position(ids[#ids])
    lowest = math.min(lowest, y)
    local ke, pe = w:energy()
    emax = math.max(emax, ke + pe)
  end }
  local m_total = 0.01 * N
  print(string.format("lowest free end y = %.3f; energy: start %.4f J, max %.4f J (rope weight %.3f N)",
    lowest, e0, emax, m_total * 9.81))
  -- a falling rope whips: the free end reaches about L below the pin
  expect.lt(lowest, Y0 - 0.8 * L, "free end swings down")
  -- no external work: total energy must not grow. Tolerance 1% of the drop's energy
  -- scale m g L/2 (the rope's potential-energy change when it hangs)
  expect.le(emax, e0 + 0.01 * m_total * 9.81 * L / 2, "no energy gained")
end)
