-- capsule_box.lua: capsule end caps and a rotated box's outside, against geometry
-- worked out by hand (not numbers read off the code): signed distances from
-- col:distance, and where a particle comes to rest on each shape.

test("a capsule's distance is to its segment: hemispherical caps beyond the ends", function()
  local w = wobble.world{}
  local r = 0.25
  local col = w:collider{ shape = "capsule", a = {0, 0, 0}, b = {1, 0, 0}, radius = r }
  expect.near(col:distance(0.5, 1, 0), 1 - r, 1e-12, "beside the middle")
  expect.near(col:distance(-1, 0, 0), 1 - r, 1e-12, "on the axis, 1 before a")
  expect.near(col:distance(2, 0, 0), 1 - r, 1e-12, "on the axis, 1 past b")
  expect.near(col:distance(1.3, 0.4, 0), 0.5 - r, 1e-12, "off b's cap: |(0.3, 0.4)| = 0.5")
  expect.near(col:distance(-0.6, 0, 0.8), 1 - r, 1e-12, "off a's cap: |(-0.6, 0, 0.8)| = 1")
end)

test("a particle dropped beside a capsule's end rests on the cap's sphere", function()
  -- a particle of radius pr dropped at x = 1.1 (0.1 past b) settles on the cap where
  -- |x - b| = R + pr: y = sqrt((R + pr)^2 - 0.1^2) (friction holds it there)
  local R, pr = 0.25, 0.05
  local w = wobble.world{ substeps = 20 }
  w:collider{ shape = "capsule", a = {0, 0, 0}, b = {1, 0, 0}, radius = R, friction = 1 }
  local p = w:particle{ pos = {1.1, 0.6, 0}, radius = pr }
  w:run{ seconds = 0.8 }
  local x, y = w:position(p)
  -- it slid a little on the cap before friction held it: on the sphere wherever it is
  expect.near(math.sqrt((x - 1) ^ 2 + y ^ 2), R + pr, 2e-3, "on the cap's sphere")
  expect.gt(x, 1, "beyond the end")
end)

-- q for a turn of `deg` degrees about the unit axis (ax, ay, az)
local function quat(deg, ax, ay, az)
  local h = math.rad(deg) / 2
  return { math.cos(h), ax * math.sin(h), ay * math.sin(h), az * math.sin(h) }
end

test("a rotated box, approached from below and from the side, stops particles at its faces", function()
  -- a box 2 x 1 x 1 (half {1, 0.5, 0.5}) turned 90 degrees about z: in the world it is
  -- 1 wide in x and 2 tall in y, faces at x = +-0.5 and y = +-1. Gravity pushes particles
  -- against its bottom face (gravity +y) and its left face (gravity +x).
  local pr = 0.05
  for _, case in ipairs{
    { g = {0, 9.81, 0}, start = {0.1, -1.5, 0.1}, axis = 2, rest = -1 - pr },
    { g = {9.81, 0, 0}, start = {-1, 0.3, -0.2}, axis = 1, rest = -0.5 - pr },
  } do
    local w = wobble.world{ gravity = case.g, substeps = 20 }
    w:collider{ shape = "box", center = {0, 0, 0}, half = {1, 0.5, 0.5}, rotation = quat(90, 0, 0, 1), friction = 1 }
    local p = w:particle{ pos = case.start, radius = pr }
    w:run{ seconds = 1 }
    local pos = { w:position(p) }
    local vel = { w:velocity(p) }
    expect.near(pos[case.axis], case.rest, 1e-3, "resting against the face")
    for k = 1, 3 do expect.near(vel[k], 0, 1e-2, "at rest") end
  end
end)
