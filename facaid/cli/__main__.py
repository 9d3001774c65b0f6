import sys

from facaid.cli import main

sys.exit(main())
