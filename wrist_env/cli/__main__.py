"""`python -m wrist_env.cli`: the same as `wrist-bench`."""

from wrist_env.cli import main

raise SystemExit(main())
