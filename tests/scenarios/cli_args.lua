-- cli_args.lua: what the command line gives every script it runs.

test("wobble is a global, require returns it", function()
  expect.eq(type(wobble), "table")
  expect.eq(require "wobble", wobble)
  expect.eq(package.loaded.wobble, wobble)
end)

test("wobble.args is a table (empty without --set)", function()
  expect.eq(type(wobble.args), "table")
  expect.eq(next(wobble.args), nil)
end)

test("test and expect are globals under wobble test", function()
  expect.eq(type(test), "function")
  expect.eq(type(expect), "table")
  expect.eq(type(expect.near), "function")
end)
