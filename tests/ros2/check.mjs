// The test scripts' one way of failing: check(condition, what) records and prints a failure and returns the condition.
export const failures = [];
export function check(ok, what) {
  if (!ok) {
    failures.push(what);
    console.log("FAIL: " + what);
  }
  return ok;
}
