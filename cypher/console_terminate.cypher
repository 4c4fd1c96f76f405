// End the transactions of a console request that ran past its time.
TERMINATE TRANSACTIONS $ids
