from robotale.cli import main

raise SystemExit(main())
