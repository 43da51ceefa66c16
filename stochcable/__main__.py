import sys

from stochcable.cli import main

sys.exit(main())
