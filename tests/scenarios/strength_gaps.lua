-- strength_gaps.lua: checks that `make mutate` (tests/mutate/) showed missing: each
-- test here kills a mutant that survived the rest of the suite.

test("a folder is not inside another whose name is its prefix (scenarios-evil is not scenarios)", function()
  -- reads are allowed under the scene's folder (tests/scenarios); its sibling
  -- tests/scenarios-evil shares the prefix but is outside (nothing is created)
  expect.error(function() io.open("../scenarios-evil/x.txt") end, "is outside the allowed folders")
  expect.error(function() io.open("../scenariosx") end, "is outside the allowed folders")
  -- the output folder, found from the rule's own message (as the user named it: its
  -- sibling can be named only when that is an absolute path, as under make test)
  local err = expect.error(function() io.open("/tmp/wobble-sandbox-never-created/x.txt", "w") end)
  local out = tostring(err):match("outside the output folder (%S+);")
  expect.truthy(out, "the message names the output folder")
  if out and out:sub(1, 1) == "/" then
    out = out:gsub("/$", "")
    expect.error(function() io.open(out .. "-evil/x.txt") end, "is outside the allowed folders")
  end
end)

test("w:distance refuses a particle linked to itself, changing nothing", function()
  local w = wobble.world{}
  local p = w:particle{ pos = {0, 0, 0} }
  w:particle{ pos = {1, 0, 0} }
  local before = w:hash()
  expect.error(function() w:distance(p, p) end, "bad argument #2 to 'distance' (a constraint needs two distinct particles)")
  expect.eq(w:stats().distances, 0)
  expect.eq(w:hash(), before)
end)

test("r:camera refuses a field of view of 180 degrees or more, and 0 or less", function()
  local r = wobble.renderer{ width = 8, height = 8, backend = "null" }
  for _, fov in ipairs{ 180, 270, 0, -10 } do
    expect.error(function() r:camera{ eye = {3, 2, 3}, target = {0, 0, 0}, fov = fov } end, "fov", "fov " .. fov)
  end
  r:camera{ eye = {3, 2, 3}, target = {0, 0, 0}, fov = 179 }
  r:camera{ eye = {3, 2, 3}, target = {0, 0, 0}, fov = 1 }
end)
