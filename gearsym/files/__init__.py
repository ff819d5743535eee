"""Files and folders: written whole (:mod:`.atomic`) or as a set (:mod:`.sets`), kept private where they hold
code (:mod:`.private`), a small JSON record sealed against change (:mod:`.sealed`), where the user's cache is
(:mod:`.cache`) and small answers kept in it (:mod:`.memo`), an output's place checked before work starts
(:mod:`.outputs`), what stands at a path that is no regular file said as what it is (:mod:`.kinds`), and the
package's own folders (:mod:`.paths`)."""
