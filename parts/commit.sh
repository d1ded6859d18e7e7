#!/bin/sh
# sh parts/commit.sh NAME "message" - commit only parts/NAME* (and parts/fuzz_NAME*), retrying
# while another session holds the git index lock.
cd "$(dirname "$0")/.." || exit 1
name=$1; msg=$2; i=0
while [ $i -lt 30 ]; do
  files=$(ls -d parts/$name* parts/*_$name* 2>/dev/null)
  if git add $files 2>/tmp/commit_err_$$ && git commit -q -m "parts/$name: $msg" -- $files 2>>/tmp/commit_err_$$; then
    echo "committed"; rm -f /tmp/commit_err_$$; exit 0; fi
  if grep -q "index.lock" /tmp/commit_err_$$; then i=$((i + 1)); sleep 2; continue; fi
  cat /tmp/commit_err_$$; rm -f /tmp/commit_err_$$; exit 1
done
echo "gave up: index lock"; exit 1
