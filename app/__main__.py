from poinsot.app.cli import main

raise SystemExit(main())
